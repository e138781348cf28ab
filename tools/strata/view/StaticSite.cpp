#include "StaticSite.hpp"

#include <unistd.h>

#include <fstream>
#include <string_view>

#include "strata/core/Error.hpp"

namespace strata::view {
namespace {

namespace fs = std::filesystem;

// Marks where index.html takes the static manifest's script (tools/strata/web/index.html).
constexpr std::string_view kStaticMarker = "<!-- strata:static -->";

std::string Base64(const std::string& bytes) {
    static constexpr char kDigits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        const size_t n = std::min<size_t>(3, bytes.size() - i);
        uint32_t word = 0;
        for (size_t k = 0; k < 3; ++k) {
            word = (word << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0U);
        }
        for (size_t k = 0; k < 4; ++k) {
            out += k <= n ? kDigits[(word >> (18 - 6 * k)) & 63U] : '=';
        }
    }
    return out;
}

// The script file that carries the answer to `path`: "/api/tile/1/-2/3/0" -> api_tile_1_-2_3_0.js.
std::string ScriptName(const std::string& path) {
    std::string name = path.substr(1);
    std::replace(name.begin(), name.end(), '/', '_');
    return name + ".js";
}

class SiteWriter {
public:
    SiteWriter(const ViewService& service, fs::path dir) : service_(service), dir_(std::move(dir)) {
        fs::create_directories(dir_ / "data");
    }

    void Write(const fs::path& relative, const std::string& text) {
        std::ofstream out(dir_ / relative, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw IoError((dir_ / relative).string() + ": cannot write");
        ++report.files;
        report.bytes += text.size();
    }

    // The answer to `path`, wrapped in a call the page's loader receives.
    void Payload(const std::string& path) {
        const Response r = service_.Get(path);
        if (r.status != 200) {
            throw IoError("static export: " + path + " answered " + std::to_string(r.status) +
                          ": " + r.body);
        }
        const bool json = r.content_type.rfind("application/json", 0) == 0;
        Write(fs::path("data") / ScriptName(path),
              "strataPayload(" + nlohmann::json(path).dump() + "," +
                  (json ? r.body : "\"" + Base64(r.body) + "\"") + ");\n");
    }

    StaticSiteReport report;

private:
    const ViewService& service_;
    fs::path dir_;
};

}  // namespace

StaticSiteReport WriteStaticSite(const ViewService& service, const fs::path& dir) {
    if (fs::exists(dir) && !(fs::is_directory(dir) && fs::is_empty(dir))) {
        throw InvalidArgumentError(dir.string() + ": exists and is not an empty folder");
    }
    const fs::path partial = dir.string() + ".partial-" + std::to_string(::getpid());
    fs::remove_all(partial);
    SiteWriter site(service, partial);
    try {
        std::vector<std::pair<int64_t, int64_t>> diffs;
        const std::vector<int64_t>& sessions = service.source().snapshots().front().sessions;
        for (size_t i = 1; i < sessions.size(); ++i)
            diffs.emplace_back(sessions[i - 1], sessions[i]);
        for (const WebAsset& a : service.assets()) {
            std::string body = a.body;
            if (a.name == "index.html") {
                const size_t at = body.find(kStaticMarker);
                if (at == std::string::npos)
                    throw FormatError("index.html lacks its static marker");
                body.replace(at, kStaticMarker.size(), "<script src=\"data/api_map.js\"></script>");
            }
            site.Write(a.name, body);
        }
        site.Write("data/api_map.js",
                   "strataPayload(\"/api/map\"," + service.Manifest(true, diffs).dump() + ");\n");
        for (const TileStats& t : service.tile_stats()) {
            for (int lod = 0; lod <= kMaxLod; ++lod) {
                site.Payload("/api/tile/" + std::to_string(t.tile.x) + "/" +
                             std::to_string(t.tile.y) + "/" + std::to_string(t.tile.version) + "/" +
                             std::to_string(lod));
            }
        }
        std::vector<std::string> changes;
        for (const auto& [a, b] : diffs)
            changes.push_back("diff/" + std::to_string(a) + "/" + std::to_string(b));
        for (const nlohmann::json& set : service.source().change_sets()) {
            changes.push_back("changeset/" + std::to_string(set.at("id").get<int64_t>()));
        }
        for (const std::string& key : changes) {
            site.Payload("/api/" + key);
            for (const auto& [x, y] : service.ChangeTiles(key)) {
                for (int lod = 0; lod <= kMaxLod; ++lod) {
                    site.Payload("/api/" + key + "/" + std::to_string(x) + "/" + std::to_string(y) +
                                 "/" + std::to_string(lod));
                }
            }
        }
        site.report.diffs = diffs.size();
        if (fs::exists(dir)) fs::remove(dir);  // the empty folder it replaces
        fs::rename(partial, dir);
    } catch (...) {
        std::error_code ignored;
        fs::remove_all(partial, ignored);
        throw;
    }
    return site.report;
}

}  // namespace strata::view
