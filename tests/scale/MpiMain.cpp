// main() of the test programs that run under `mpirun -n N` (and alone): every rank runs every
// test, so each test's collectives line up; the program fails on every rank when a test failed
// on any (docs/scale.md, "Tests").
#include <gtest/gtest.h>

#include "MpiTest.hpp"

namespace strata::test {

const pipeline::Ranks* g_ranks = nullptr;

const pipeline::Ranks& TestRanks() { return *g_ranks; }

}  // namespace strata::test

int main(int argc, char** argv) {
    const strata::pipeline::Ranks ranks = strata::pipeline::Ranks::FromEnvironment(&argc, &argv);
    strata::test::g_ranks = &ranks;
    ::testing::InitGoogleTest(&argc, argv);
    if (!ranks.root()) {
        // One report: the other ranks print only their failures.
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    const bool ok = RUN_ALL_TESTS() == 0;
    return ranks.AllOk(ok) ? 0 : 1;
}
