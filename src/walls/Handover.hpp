#pragma once
// What one WallAssembler hands another (private to the walls module): its counts, judged parts,
// waiting pieces and fitted walls, as bytes for a process of the same job (core/Bytes.hpp).
#include <string>
#include <utility>
#include <vector>

#include "Pieces.hpp"
#include "strata/walls/Walls.hpp"

namespace strata::walls::detail {

[[nodiscard]] std::string EncodeHandover(const WallStats& stats,
                                         const std::vector<std::pair<PartKey, WallPart>>& parts,
                                         const std::vector<std::pair<PartKey, Piece>>& pieces,
                                         const std::vector<std::pair<PartKey, Wall>>& walls);

/// Adds what EncodeHandover wrote to these. @throw FormatError when the bytes are cut short.
void DecodeHandover(const std::string& bytes, WallStats& stats,
                    std::vector<std::pair<PartKey, WallPart>>& parts,
                    std::vector<std::pair<PartKey, Piece>>& pieces,
                    std::vector<std::pair<PartKey, Wall>>& walls);

}  // namespace strata::walls::detail
