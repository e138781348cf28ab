// Opening a map whose catalog.sqlite was replaced by the input (seed: the catalog of a small
// valid map): SQLite's own checks, then strata's reading of settings, sessions, tile versions
// and checksums. Open + Latest + ReadFused + ReadLayer + LoadMap + Check must refuse
// (fuzz::Refusal) or succeed. The catalog is restored after each input.
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "FuzzSupport.hpp"
#include "MapTemplate.hpp"

namespace {

namespace fs = std::filesystem;

struct Template {
    fs::path dir;
    std::string catalog;  // original bytes of catalog.sqlite
};

const Template& TheMap() {
    static const Template t = [] {
        Template made;
        made.dir = strata::fuzz::ScratchDir() / "map";
        (void)strata::fuzz::CreateSmallMap(made.dir);
        std::ifstream in(made.dir / "catalog.sqlite", std::ios::binary);
        made.catalog.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        return made;
    }();
    return t;
}

void WriteCatalog(const Template& t, const std::string& bytes) {
    std::error_code ec;
    for (const char* leftover : {"catalog.sqlite-wal", "catalog.sqlite-shm"}) {
        fs::remove(t.dir / leftover, ec);
    }
    strata::fuzz::WriteBytes(t.dir / "catalog.sqlite", bytes.data(), bytes.size());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    (void)TheMap();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const Template& t = TheMap();
    WriteCatalog(t, std::string(reinterpret_cast<const char*>(data), size));
    (void)strata::fuzz::ReadWholeMap(t.dir);
    WriteCatalog(t, t.catalog);
    return 0;
}
