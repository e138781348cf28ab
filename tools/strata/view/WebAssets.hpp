#pragma once
// The files of the page: its own (compiled into the program from tools/strata/web/) and three.js,
// read from Debian's libjs-three where the package installs it, never copied into the repository.

#include <string>
#include <vector>

namespace strata::view {

/// Where Debian's libjs-three installs three.js (r111).
inline constexpr const char* kThreeDir = "/usr/share/javascript/three";

struct WebAsset {
    std::string name;  ///< served at "/" + name; "index.html" also at "/"
    std::string content_type;
    std::string body;
};

/// The page's files and three.js (three.min.js and its OrbitControls.js).
/// @throw NotFoundError naming the file and the package when three.js is not installed.
[[nodiscard]] std::vector<WebAsset> LoadWebAssets();

}  // namespace strata::view
