// Opening a map whose tile file was replaced by the input, as a damaged disk, a copy gone wrong
// or a swapped file would leave it: the catalog still records the original size and XXH64
// checksum, and Open + Latest + ReadFused + ReadLayer + LoadMap + Check must refuse the file with a
// std::exception (or succeed) before OpenVDB parses it. The tile is restored after each input.
//
// STRATA_FUZZ_MAP_FORGE=1 also records each input's size and checksum in the catalog (a forged
// or buggy-writer tile), so the bytes reach OpenVDB's parser and DecodeFused. Off by default:
// OpenVDB 10 itself has undefined behaviour on such input (docs/reliability.md, Fuzzing).
#include <sqlite3.h>
#include <xxhash.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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
    std::string tile;      // relative path of the fuzzed tile file
    std::string original;  // its bytes
    bool forge = false;
};

const Template& TheMap() {
    static const Template t = [] {
        Template made;
        made.dir = strata::fuzz::ScratchDir() / "map";
        made.tile = strata::fuzz::CreateSmallMap(made.dir);
        std::ifstream in(made.dir / made.tile, std::ios::binary);
        made.original.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        const char* forge = std::getenv("STRATA_FUZZ_MAP_FORGE");
        made.forge = forge != nullptr && std::strcmp(forge, "1") == 0;
        return made;
    }();
    return t;
}

// Records `bytes` as the size and checksum of the tile file in the catalog (harness only: the
// library never edits a tile version).
void RecordInCatalog(const Template& t, const std::string& bytes) {
    sqlite3* db = nullptr;
    const std::string catalog = (t.dir / "catalog.sqlite").string();
    if (sqlite3_open_v2(catalog.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
        sqlite3_close(db);
        throw std::logic_error("fuzz harness: cannot open " + catalog);
    }
    char hex[17];
    std::snprintf(hex, sizeof(hex), "%016" PRIx64,
                  static_cast<uint64_t>(XXH64(bytes.data(), bytes.size(), 0)));
    const std::string sql = "PRAGMA synchronous = OFF; UPDATE tile_versions SET byte_size = " +
                            std::to_string(bytes.size()) + ", checksum = '" + hex +
                            "' WHERE file = '" + t.tile + "';";
    const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr);
    sqlite3_close(db);
    if (rc != SQLITE_OK) throw std::logic_error("fuzz harness: cannot edit " + catalog);
}

void WriteTile(const Template& t, const std::string& bytes) {
    strata::fuzz::WriteBytes(t.dir / t.tile, bytes.data(), bytes.size());
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    (void)TheMap();
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const Template& t = TheMap();
    const std::string input(reinterpret_cast<const char*>(data), size);
    WriteTile(t, input);
    // The catalog records the original's size and checksum: Check must report any other bytes
    // (and nothing when the input is the original).
    const auto report = strata::fuzz::ReadWholeMap(t.dir);
    if (report) {
        strata::fuzz::Expect(report->ok() == (input == t.original),
                             "Check() missed a replaced tile or flagged the original");
    }
    if (t.forge) {
        RecordInCatalog(t, input);
        (void)strata::fuzz::ReadWholeMap(t.dir);
        RecordInCatalog(t, t.original);
    }
    WriteTile(t, t.original);
    return 0;
}
