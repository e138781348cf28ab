#include "WebAssets.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>

#include "strata/core/Error.hpp"

namespace strata::view {
namespace detail {
// Generated at build time from tools/strata/web/ (EmbedFiles.cmake).
const std::vector<std::pair<const char*, std::string_view>>& EmbeddedWebFiles();
}  // namespace detail

namespace {

std::string ContentType(const std::string& name) {
    const std::string ext = std::filesystem::path(name).extension().string();
    if (ext == ".html") return "text/html; charset=utf-8";
    // Not "text/javascript": cpp-httplib compresses text/* and bare application/javascript with
    // brotli at its slowest quality (4 s for three.js), for every request.
    if (ext == ".js") return "application/javascript; charset=utf-8";
    if (ext == ".css") return "text/css; charset=utf-8";
    return "application/octet-stream";
}

std::string ReadThree(const std::string& relative) {
    const std::filesystem::path path = std::filesystem::path(kThreeDir) / relative;
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    if (!(in && text << in.rdbuf())) {
        throw NotFoundError(path.string() +
                            ": three.js is missing; install Debian's libjs-three "
                            "(tools/setup.sh does)");
    }
    return text.str();
}

}  // namespace

std::vector<WebAsset> LoadWebAssets() {
    std::vector<WebAsset> assets;
    for (const auto& [name, bytes] : detail::EmbeddedWebFiles()) {
        assets.push_back({name, ContentType(name), std::string(bytes)});
    }
    // The classic (non-module) builds: module scripts do not load from file://, the static
    // export's case.
    for (const auto& [name, relative] :
         {std::pair{"three.min.js", "build/three.min.js"},
          std::pair{"OrbitControls.js", "examples/js/controls/OrbitControls.js"}}) {
        assets.push_back({name, ContentType(name), ReadThree(relative)});
    }
    return assets;
}

}  // namespace strata::view
