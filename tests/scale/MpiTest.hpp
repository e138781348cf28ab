#pragma once
// The ranks the test program runs on (MpiMain.cpp): one process under plain CTest, N under
// `mpirun -n N`.

#include "strata/pipeline/Ranks.hpp"

namespace strata::test {

[[nodiscard]] const pipeline::Ranks& TestRanks();

}  // namespace strata::test
