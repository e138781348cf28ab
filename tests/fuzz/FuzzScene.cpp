// The simulator's JSON scene file: parsing, generators (garage, building), edits, validation.
#include "FuzzSupport.hpp"
#include "strata/sim/SceneSpec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace strata;  // NOLINT(google-build-using-namespace): harness
    const auto path = fuzz::WriteInput(data, size, "scene.json");
    fuzz::Refusal([&] {
        const sim::SceneSpec spec = sim::LoadSceneSpec(path);
        for (size_t s = 0; s < spec.sessions.size(); ++s) (void)sim::ObjectsOfSession(spec, s);
    });
    return 0;
}
