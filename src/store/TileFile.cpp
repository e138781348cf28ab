#include "TileFile.hpp"

#include <fcntl.h>
#include <openvdb/io/Stream.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "strata/core/Error.hpp"
#include "strata/io/AtomicFile.hpp"

namespace strata::store {
namespace {

std::atomic<uint64_t> g_fused_bytes{0};
std::atomic<uint64_t> g_layer_bytes{0};
std::atomic<uint64_t> g_product_bytes{0};
std::atomic<uint64_t> g_files{0};

}  // namespace

ReadCounters BytesRead() {
    return {g_fused_bytes.load(), g_layer_bytes.load(), g_product_bytes.load(), g_files.load()};
}

namespace detail {
namespace {

namespace fs = std::filesystem;
constexpr const char* kTileKeyMeta = "strata_tile";

std::string KeyText(const TileKey& key) {
    return std::to_string(key.x) + "_" + std::to_string(key.y);
}

// Stream buffers over a std::string without copying it (std::stringstream copies the bytes in
// and, before C++20, out again: a tile read or write paid for two extra copies of the file).
class StringSource : public std::streambuf {
public:
    explicit StringSource(const std::string& bytes) {
        char* begin = const_cast<char*>(bytes.data());  // read only: the get area never writes
        setg(begin, begin, begin + bytes.size());
    }
};

class StringSink : public std::streambuf {
public:
    explicit StringSink(std::string& out) : out_(out) {}

protected:
    int_type overflow(int_type c) override {
        if (!traits_type::eq_int_type(c, traits_type::eof())) out_.push_back(static_cast<char>(c));
        return traits_type::not_eof(c);
    }
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        out_.append(s, static_cast<size_t>(n));
        return n;
    }

private:
    std::string& out_;
};

void Count(FileKind kind, uint64_t bytes) {
    (kind == FileKind::kFused    ? g_fused_bytes
     : kind == FileKind::kLayers ? g_layer_bytes
                                 : g_product_bytes) += bytes;
    ++g_files;
}

}  // namespace

std::string TileDirName(const TileKey& key) { return "tiles/" + KeyText(key); }
std::string FusedFileName(const TileKey& key, int64_t version) {
    return TileDirName(key) + "/f" + std::to_string(version) + ".vdb";
}
std::string LayerFileName(const TileKey& key, int64_t session) {
    return TileDirName(key) + "/s" + std::to_string(session) + ".vdb";
}
std::string ProductFileName(const TileKey& key, int64_t commit) {
    return TileDirName(key) + "/p" + std::to_string(commit) + ".vdb";
}

namespace {
constexpr std::array<std::pair<LayerKind, std::string_view>, 5> kLayerKinds = {{
    {LayerKind::kOccupied, "occupied"},
    {LayerKind::kFree, "free"},
    {LayerKind::kCrossed, "crossed"},
    {LayerKind::kGrazed, "grazed"},
    {LayerKind::kHit, "hit"},
}};
}  // namespace

std::string LayerName(int64_t session, LayerKind kind) {
    for (const auto& [k, name] : kLayerKinds) {
        if (k == kind) return "session_" + std::to_string(session) + "_" + std::string(name);
    }
    throw InvalidArgumentError("unknown session layer kind");
}

std::pair<int64_t, LayerKind> ParseLayerName(const std::string& name) {
    constexpr std::string_view prefix = "session_";
    const std::pair<int64_t, LayerKind> none{0, LayerKind::kOccupied};
    if (name.compare(0, prefix.size(), prefix) != 0) return none;
    const size_t end = name.find('_', prefix.size());
    if (end == std::string::npos || end == prefix.size() || end - prefix.size() > 18) return none;
    const std::string id = name.substr(prefix.size(), end - prefix.size());
    if (!std::all_of(id.begin(), id.end(), [](char c) { return c >= '0' && c <= '9'; })) {
        return none;
    }
    const std::string kind = name.substr(end + 1);
    for (const auto& [k, text] : kLayerKinds) {
        if (kind == text) return {std::stoll(id), k};
    }
    return none;
}

uint64_t Checksum(const std::string& bytes) { return XXH64(bytes.data(), bytes.size(), 0); }

EncodedFile EncodeGrids(const openvdb::GridPtrVec& grids, const TileKey& key) {
    openvdb::MetaMap meta;
    meta.insertMeta(kTileKeyMeta, openvdb::StringMetadata(KeyText(key)));
    EncodedFile out;
    StringSink sink(out.bytes);
    std::ostream os(&sink);
    openvdb::io::Stream stream(os);
    // Active-mask compression only: Blosc made files 1.7x smaller but cost 5-7 points of the
    // commit overhead and a third of a tile read's time (docs/bench.md, Store).
    stream.setCompression(openvdb::io::COMPRESS_ACTIVE_MASK);
    stream.write(grids, meta);
    if (!os) throw IoError("tile " + KeyText(key) + ": cannot serialise");
    out.checksum = Checksum(out.bytes);
    return out;
}

FileRef WriteGrids(const fs::path& dir, const std::string& file, const openvdb::GridPtrVec& grids,
                   const TileKey& key) {
    const EncodedFile encoded = EncodeGrids(grids, key);
    WriteTileFile(dir / file, encoded.bytes);
    FileRef ref;
    ref.file = file;
    ref.bytes = encoded.bytes.size();
    ref.checksum = encoded.checksum;
    return ref;
}

void WriteTileFile(const fs::path& path, const std::string& bytes) {
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    if (ec) {
        throw IoError("cannot create '" + path.parent_path().string() + "': " + ec.message());
    }
    io::WriteFileAtomically(path, [&](std::ostream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    });
}

std::string ReadVerifiedFile(const fs::path& dir, const FileRef& ref, FileKind kind) {
    const fs::path path = dir / ref.file;
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::error_code ec;
        if (!fs::exists(path, ec)) throw NotFoundError(path.string() + ": missing file");
        throw IoError(path.string() + ": unreadable file (" + std::strerror(errno) + ")");
    }
    in.seekg(0, std::ios::end);
    const auto size = static_cast<uint64_t>(in.tellg());
    if (size != ref.bytes) {
        throw FormatError(path.string() + ": file has " + std::to_string(size) +
                          " bytes, the catalog recorded " + std::to_string(ref.bytes) +
                          " (truncated or replaced)");
    }
    std::string data(size, '\0');
    in.seekg(0);
    in.read(data.data(), static_cast<std::streamsize>(size));
    if (!in) throw IoError(path.string() + ": read error");
    Count(kind, size);
    if (Checksum(data) != ref.checksum) {
        throw FormatError(path.string() + ": file is corrupt (checksum mismatch)");
    }
    return data;
}

openvdb::GridPtrVec DecodeGrids(const std::string& bytes, const TileKey& key,
                                const fs::path& path) {
    openvdb::initialize();
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr meta;
    try {
        StringSource source(bytes);
        std::istream is(&source);
        // Delayed loading copies the stream to a temporary file under /tmp (left behind when the
        // process is killed) and gave inactive voxels arbitrary values, which the integrator then
        // added to when it activated them.
        openvdb::io::Stream stream(is, /*delayLoad=*/false);
        grids = stream.getGrids();
        meta = stream.getMetadata();
    } catch (const std::exception& e) {
        throw FormatError(path.string() + ": OpenVDB cannot read the file (" + e.what() + ")");
    }
    const auto tag = meta ? meta->getMetadata<openvdb::StringMetadata>(kTileKeyMeta) : nullptr;
    if (!tag || tag->value() != KeyText(key) || !grids) {
        throw FormatError(path.string() + ": not a file of tile " + KeyText(key));
    }
    return *grids;
}

core::VoxelMap DecodeFused(const std::string& bytes, const TileKey& key, const fs::path& path) {
    try {
        return core::VoxelMap::FromGrids(DecodeGrids(bytes, key, path));
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw FormatError(path.string() + ": " + e.what());
    }
}

SessionLayer DecodeLayer(const std::string& bytes, const TileKey& key, int64_t session,
                         const fs::path& path) {
    SessionLayer layer;
    layer.session = session;
    for (const auto& grid : DecodeGrids(bytes, key, path)) {
        const auto [id, kind] = ParseLayerName(grid->getName());
        auto bool_grid = openvdb::gridPtrCast<openvdb::BoolGrid>(grid);
        if (id != session || !bool_grid) {
            throw FormatError(path.string() + ": '" + grid->getName() +
                              "' is not a layer of session " + std::to_string(session));
        }
        switch (kind) {
            case LayerKind::kOccupied:
                layer.occupied = bool_grid;
                break;
            case LayerKind::kFree:
                layer.free = bool_grid;
                break;
            case LayerKind::kCrossed:
                layer.crossed = bool_grid;
                break;
            case LayerKind::kGrazed:
                layer.grazed = bool_grid;
                break;
            case LayerKind::kHit:
                layer.hit = bool_grid;
                break;
        }
    }
    const int since6 = !!layer.crossed + !!layer.grazed + !!layer.hit;
    if (!layer.occupied || !layer.free || (since6 != 0 && since6 != 3)) {
        throw FormatError(path.string() + ": session " + std::to_string(session) +
                          " lacks some of its layers (occupied, free; crossed, grazed, hit)");
    }
    return layer;
}

void SyncDirectory(const fs::path& dir) {
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) {
        throw IoError(dir.string() + ": cannot open to flush (" + std::strerror(errno) + ")");
    }
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) {
        throw IoError(dir.string() + ": flushing the directory failed (" + std::strerror(errno) +
                      ")");
    }
}

}  // namespace detail
}  // namespace strata::store
