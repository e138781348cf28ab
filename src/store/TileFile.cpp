#include "TileFile.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <openvdb/io/Stream.h>
#include <sstream>
#include <stdexcept>

#include "strata/io/AtomicFile.hpp"

namespace strata::store::detail {
namespace {

namespace fs = std::filesystem;
constexpr const char* kTileKeyMeta = "strata_tile";

std::string KeyText(const TileKey& key) {
    return std::to_string(key.x) + "_" + std::to_string(key.y);
}

// "session_<id>_occupied" -> (id, true); anything else -> id 0.
std::pair<int64_t, bool> ParseLayerName(const std::string& name) {
    constexpr std::string_view prefix = "session_";
    if (name.compare(0, prefix.size(), prefix) != 0) return {0, false};
    const size_t end = name.find('_', prefix.size());
    if (end == std::string::npos || end == prefix.size()) return {0, false};
    const std::string id = name.substr(prefix.size(), end - prefix.size());
    if (!std::all_of(id.begin(), id.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return {0, false};
    }
    const std::string kind = name.substr(end + 1);
    if (kind != "occupied" && kind != "free") return {0, false};
    return {std::stoll(id), kind == "occupied"};
}

}  // namespace

std::string LayerName(int64_t session, bool occupied) {
    return "session_" + std::to_string(session) + (occupied ? "_occupied" : "_free");
}

uint64_t Checksum(const std::string& bytes) { return XXH64(bytes.data(), bytes.size(), 0); }

EncodedTile EncodeGrids(const openvdb::GridPtrVec& grids, const TileKey& key) {
    openvdb::MetaMap meta;
    meta.insertMeta(kTileKeyMeta, openvdb::StringMetadata(KeyText(key)));
    std::ostringstream os(std::ios::binary);
    openvdb::io::Stream stream(os);
    // Active-mask compression only: Blosc made files 1.7x smaller but cost 5-7 points of the
    // commit overhead and a third of a tile read's time (docs/bench.md, Store).
    stream.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
    stream.write(grids, meta);
    if (!os) throw std::runtime_error("tile " + KeyText(key) + ": cannot serialise");
    EncodedTile out;
    out.bytes = std::move(os).str();
    out.checksum = Checksum(out.bytes);
    return out;
}

EncodedTile EncodeTile(const Tile& tile) {
    openvdb::GridPtrVec grids = tile.fused.Grids();
    for (const SessionLayer& layer : tile.layers) {
        layer.occupied->setName(LayerName(layer.session, true));
        layer.free->setName(LayerName(layer.session, false));
        grids.push_back(layer.occupied);
        grids.push_back(layer.free);
    }
    grids.insert(grids.end(), tile.products.begin(), tile.products.end());
    return EncodeGrids(grids, tile.key);
}

void WriteTileFile(const fs::path& path, const std::string& bytes) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    if (ec) {
        throw std::runtime_error("cannot create '" + path.parent_path().string() +
                                 "': " + ec.message());
    }
    io::WriteFileAtomically(path, [&](std::ostream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    });
}

std::string ReadVerifiedFile(const fs::path& path, uint64_t bytes, uint64_t checksum) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": missing or unreadable tile file");
    std::string data;
    in.seekg(0, std::ios::end);
    const auto size = static_cast<uint64_t>(in.tellg());
    if (size != bytes) {
        throw std::runtime_error(path.string() + ": tile file has " + std::to_string(size) +
                                 " bytes, the catalog recorded " + std::to_string(bytes) +
                                 " (truncated or replaced)");
    }
    data.resize(size);
    in.seekg(0);
    in.read(data.data(), static_cast<std::streamsize>(size));
    if (!in) throw std::runtime_error(path.string() + ": read error");
    if (Checksum(data) != checksum) {
        throw std::runtime_error(path.string() + ": tile file is corrupt (checksum mismatch)");
    }
    return data;
}

openvdb::GridPtrVec DecodeGrids(const std::string& bytes, const TileKey& key,
                                const fs::path& path) {
    openvdb::initialize();
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr meta;
    try {
        std::istringstream is(bytes, std::ios::binary);
        // Delayed loading copies the stream to a temporary file under /tmp (left behind when the
        // process is killed) and gave inactive voxels arbitrary values, which the integrator then
        // added to when it activated them.
        openvdb::io::Stream stream(is, /*delayLoad=*/false);
        grids = stream.getGrids();
        meta = stream.getMetadata();
    } catch (const std::exception& e) {
        throw std::runtime_error(path.string() + ": OpenVDB cannot read the tile (" + e.what() +
                                 ")");
    }
    const auto tag = meta ? meta->getMetadata<openvdb::StringMetadata>(kTileKeyMeta) : nullptr;
    if (!tag || tag->value() != KeyText(key) || !grids) {
        throw std::runtime_error(path.string() + ": not the file of tile " + KeyText(key));
    }
    return *grids;
}

Tile DecodeTile(const std::string& bytes, const TileKey& key, const fs::path& path) {
    const openvdb::GridPtrVec grids = DecodeGrids(bytes, key, path);
    Tile tile;
    tile.key = key;
    openvdb::GridPtrVec fused;
    for (const auto& grid : grids) {
        // Plain variables, not a structured binding: clang before 16 cannot capture a binding
        // in the lambda below (the fuzz build, tools/fuzz.sh, compiles with clang 14).
        const std::pair<int64_t, bool> layer_of = ParseLayerName(grid->getName());
        const int64_t session = layer_of.first;
        const bool occupied = layer_of.second;
        if (session == 0) {
            fused.push_back(grid);
            continue;
        }
        auto bool_grid = openvdb::gridPtrCast<openvdb::BoolGrid>(grid);
        if (!bool_grid) {
            throw std::runtime_error(path.string() + ": layer '" + grid->getName() +
                                     "' is not a BoolGrid");
        }
        auto it = std::find_if(tile.layers.begin(), tile.layers.end(),
                               [&](const SessionLayer& l) { return l.session == session; });
        if (it == tile.layers.end()) it = tile.layers.insert(tile.layers.end(), SessionLayer{session, nullptr, nullptr});
        (occupied ? it->occupied : it->free) = bool_grid;
    }
    for (const SessionLayer& layer : tile.layers) {
        if (!layer.occupied || !layer.free) {
            throw std::runtime_error(path.string() + ": session " + std::to_string(layer.session) +
                                     " has only one of its two layers");
        }
    }
    std::sort(tile.layers.begin(), tile.layers.end(),
              [](const SessionLayer& a, const SessionLayer& b) { return a.session < b.session; });
    try {
        tile.fused = core::VoxelMap::FromGrids(fused);
    } catch (const std::exception& e) {
        throw std::runtime_error(path.string() + ": " + e.what());
    }
    for (const auto& grid : fused) {
        if (!core::VoxelMap::IsMapGrid(grid->getName())) {
            tile.products.push_back(grid);
        }
    }
    return tile;
}

void SyncDirectory(const fs::path& dir) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) {
        throw std::runtime_error(dir.string() + ": cannot open to flush (" +
                                 std::strerror(errno) + ")");
    }
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) {
        throw std::runtime_error(dir.string() + ": flushing the directory failed (" +
                                 std::strerror(errno) + ")");
    }
}

}  // namespace strata::store::detail
