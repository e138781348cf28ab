#pragma once

#include <filesystem>
#include <functional>
#include <ostream>

namespace strata::io {

/// @brief Writes `path` all or nothing: `write` fills a temporary file in the same directory, which
/// is flushed, closed, checked, fsync'ed and renamed over `path` only when everything succeeded.
/// @note Throws strata::IoError naming `path` (and the reason) when the file cannot be created,
/// when `write` throws, or when the stream is bad after writing or closing (a full disk); the
/// temporary file is removed and an existing `path` is left untouched.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

}  // namespace strata::io
