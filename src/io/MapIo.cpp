#include "strata/io/MapIo.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <openvdb/io/Stream.h>
#include <stdexcept>

#include "AtomicFile.hpp"

namespace strata::io {
namespace {

namespace fs = std::filesystem;
constexpr const char* kSessionsKey = "strata_sessions";
constexpr const char* kFormatKey = "strata_format";
constexpr const char* kFormat = "strata-map-dir 1";

void FsyncPath(const fs::path& path) {
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) throw std::runtime_error(path.string() + ": cannot open to flush to disk");
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) throw std::runtime_error(path.string() + ": flushing to disk failed");
}

std::string SessionsJson(const std::vector<MapSession>& sessions) {
    nlohmann::json j = nlohmann::json::array();
    for (const MapSession& s : sessions) {
        j.push_back({{"id", s.id}, {"name", s.name}, {"source", s.source}, {"scans", s.scans},
                     {"points", s.points}, {"created_utc", s.created_utc}});
    }
    return j.dump();
}

std::vector<MapSession> ParseSessions(const std::string& text, const fs::path& file) {
    std::vector<MapSession> sessions;
    try {
        for (const auto& j : nlohmann::json::parse(text)) {
            MapSession s;
            s.id = j.at("id").get<int>();
            s.name = j.at("name").get<std::string>();
            s.source = j.at("source").get<std::string>();
            s.scans = j.at("scans").get<size_t>();
            s.points = j.at("points").get<size_t>();
            s.created_utc = j.at("created_utc").get<std::string>();
            sessions.push_back(s);
        }
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(file.string() + ": the session list is damaged (" + e.what() +
                                 ")");
    }
    return sessions;
}

}  // namespace

fs::path MapGridFile(const fs::path& dir) { return dir / "map.vdb"; }

bool IsMapDirectory(const fs::path& dir) { return fs::is_regular_file(MapGridFile(dir)); }

MapDirectory LoadMapDirectory(const fs::path& dir) {
    const fs::path file = MapGridFile(dir);
    if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": no such map directory");
    if (!fs::is_regular_file(file)) {
        throw std::runtime_error(dir.string() + ": not a strata map (no map.vdb inside)");
    }
    openvdb::initialize();
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr meta;
    try {
        std::ifstream in(file, std::ios::binary);
        openvdb::io::Stream stream(in);
        grids = stream.getGrids();
        meta = stream.getMetadata();
    } catch (const std::exception& e) {
        throw std::runtime_error(file.string() + ": cannot read the map (" + e.what() + ")");
    }
    const auto tag = meta ? meta->getMetadata<openvdb::StringMetadata>(kFormatKey) : nullptr;
    if (!tag || tag->value() != kFormat) {
        throw std::runtime_error(file.string() + ": not a strata map (format tag missing or "
                                 "unknown)");
    }
    MapDirectory out;
    try {
        out.map = core::VoxelMap::FromGrids(*grids);
    } catch (const std::exception& e) {
        throw std::runtime_error(file.string() + ": " + e.what());
    }
    const auto sessions = meta->getMetadata<openvdb::StringMetadata>(kSessionsKey);
    out.sessions = ParseSessions(sessions ? sessions->value() : "[]", file);
    return out;
}

void SaveMapDirectory(const MapDirectory& map, const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw std::runtime_error(dir.string() + ": cannot create directory: " + ec.message());
    const fs::path file = MapGridFile(dir);
    openvdb::MetaMap meta;
    meta.insertMeta(kFormatKey, openvdb::StringMetadata(kFormat));
    meta.insertMeta(kSessionsKey, openvdb::StringMetadata(SessionsJson(map.sessions)));
    detail::WriteFileAtomically(file, [&](std::ostream& out) {
        openvdb::io::Stream(out).write(map.map.Grids(), meta);
    });
    FsyncPath(dir);
}

}  // namespace strata::io
