// Step 2 of integrating a scan: mark the voxels every ray crosses (exact 3D DDA, Amanatides-Woo),
// in parallel over rays into thread-local bitmaps, then turn the bitmaps into VDB masks.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <unordered_set>

#include "RayMarking.hpp"
#include "Scratch.hpp"
#include "TraceRay.hpp"
#include "strata/core/Error.hpp"

namespace strata::integration::detail {
namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;
constexpr size_t kRayGrain = 2048;

// The bitmaps (Scratch.hpp) are 64-bit words: x86 masks a 64-bit shift count itself, so a mark
// is one instruction shorter than with bytes. On little-endian machines the words read as bytes
// give bit `pos` at byte pos / 8, bit pos % 8, which is what GatherBrick reads.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "bitmap bytes assume little endian");

size_t RayCount(const PreparedScan& scan) { return scan.points_only ? 0 : scan.ends.size(); }

// One 8x8x8 brick of a bitmap as the eight 64-bit words of a VDB leaf mask (offset x<<6|y<<3|z:
// word = x, byte = y, bit = z), which is the bitmap's byte layout since z is fastest.
void GatherBrick(const VoxelBox& box, const uint8_t* bytes, int64_t bx, int64_t by, int64_t bz,
                 uint64_t words[8]) {
    const int64_t row = box.nz >> 3;    // bytes of one (x, y) column of the box
    const int64_t slab = box.ny * row;  // bytes of one x slab
    const uint8_t* base = bytes + bx * slab + by * row + (bz >> 3);
    for (int64_t x = 0; x < 8; ++x) {
        const uint8_t* p = base + x * slab;
        uint64_t w = 0;
        for (int64_t y = 0; y < 8; ++y) w |= uint64_t{p[y * row]} << (8 * y);
        words[x] = w;
    }
}

// Which bricks of the column (bx, by, every z) have a bit set in any of `bitmaps`: `any[k]` for
// the brick at z = 8k; false when none has. Each of the column's 8 x-slabs holds its 8 rows of z
// next to each other (nz bytes from a multiple of 8), so the slabs OR together word by word, then
// the rows byte by byte: a few hundred instructions where the byte gathers of every brick cost
// a few thousand, and most bricks of a scan's box are empty (its corners, the gaps between far
// rays, the sky).
bool FindBricks(const VoxelBox& box, const std::vector<const uint64_t*>& bitmaps, int64_t bx,
                int64_t by, std::vector<uint64_t>& acc, std::vector<uint8_t>& any) {
    const int64_t row = box.nz >> 3, slab = box.ny * row;
    acc.assign(static_cast<size_t>(row), 0);  // nz bytes as words
    for (const uint64_t* bits : bitmaps) {
        for (int64_t x = bx; x < bx + 8; ++x) {
            const uint64_t* p = bits + ((x * slab + by * row) >> 3);
            for (int64_t w = 0; w < row; ++w) acc[w] |= p[w];
        }
    }
    const auto* bytes = reinterpret_cast<const uint8_t*>(acc.data());
    any.resize(static_cast<size_t>(row));
    uint8_t all = 0;
    for (int64_t k = 0; k < row; ++k) {
        uint8_t b = 0;
        for (int64_t y = 0; y < 8; ++y) b |= bytes[y * row + k];
        any[k] = b;
        all |= b;
    }
    return all != 0;
}

// Zeroes the bytes of the column (bx, by, every z) in a bitmap: its 8 x-slabs hold the column's
// 8 rows of z next to each other. What FindBricks found empty is zero already.
void ClearColumn(const VoxelBox& box, uint64_t* bits, int64_t bx, int64_t by) {
    const int64_t row = box.nz >> 3, slab = box.ny * row;
    auto* bytes = reinterpret_cast<uint8_t*>(bits);
    for (int64_t x = bx; x < bx + 8; ++x) {
        std::memset(bytes + x * slab + by * row, 0, static_cast<size_t>(8 * row));
    }
}

ScanMasks MarkDense(const PreparedScan& scan, bool wide, const NearEndMargin& margin,
                    Bitmaps& bitmaps) {
    const VoxelBox& box = scan.box;
    const auto n_words = static_cast<size_t>(box.size() / 64);
    if (!bitmaps.clean) bitmaps.ClearAll();
    bitmaps.clean = false;
    for (Bitmap& b : bitmaps.free) b.used = false;
    for (Bitmap& b : bitmaps.near_end) b.used = false;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, RayCount(scan), kRayGrain),
        [&](const tbb::blocked_range<size_t>& range) {
            Bitmap& mine = bitmaps.free.local();
            mine.used = true;
            uint64_t* const bits = mine.Zeroed(n_words);
            const auto mark = [bits](int64_t pos) { bits[pos >> 6] |= uint64_t{1} << (pos & 63); };
            if (margin.metres <= 0.0) {
                wide ? TraceRaysWide(scan, range, bits) : TraceRays(scan, range, mark, bits);
                return;
            }
            Bitmap& near = bitmaps.near_end.local();
            near.used = true;
            uint64_t* const near_bits = near.Zeroed(n_words);
            const auto mark_near = [near_bits](int64_t pos) {
                near_bits[pos >> 6] |= uint64_t{1} << (pos & 63);
            };
            wide ? TraceRaysWide(scan, range, bits, margin, near_bits)
                 : TraceRays(scan, range, mark, bits, margin, mark_near);
        });
    uint64_t* const occupied_words = bitmaps.occupied.Zeroed(n_words);
    for (const int64_t pos : scan.endpoint_pos) {
        occupied_words[pos >> 6] |= uint64_t{1} << (pos & 63);
    }
    const auto* occupied_bytes = reinterpret_cast<const uint8_t*>(occupied_words);

    // Bricks to leaves, parallel over x-slabs of bricks; free minus occupied (occupied wins).
    // Each column of bricks is cleared once read: the bitmaps are zero again for the next scan.
    std::vector<const uint8_t*> locals, near_locals;
    std::vector<uint64_t*> all_words = {occupied_words};
    for (Bitmap& b : bitmaps.free) {
        if (!b.used) continue;  // a thread that walked no ray of this scan: all zero
        locals.push_back(reinterpret_cast<const uint8_t*>(b.words.data()));
        all_words.push_back(b.words.data());
    }
    for (Bitmap& b : bitmaps.near_end) {
        if (!b.used) continue;
        near_locals.push_back(reinterpret_cast<const uint8_t*>(b.words.data()));
        all_words.push_back(b.words.data());
    }
    const bool crossed = margin.metres > 0.0;
    const std::vector<const uint64_t*> read_words(all_words.begin(), all_words.end());
    // Each thread fills its own trees; merging them afterwards only moves nodes.
    tbb::enumerable_thread_specific<openvdb::MaskTree> free_trees, occ_trees, crossed_trees;
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, box.nx / 8), [&](const auto& range) {
        openvdb::MaskTree& my_free = free_trees.local();
        openvdb::MaskTree& my_occ = occ_trees.local();
        openvdb::MaskTree& my_crossed = crossed_trees.local();
        uint64_t occ[8], fre[8], tmp[8], cro[8];
        std::vector<uint64_t> acc;
        std::vector<uint8_t> any;
        for (int64_t bx = range.begin() * 8; bx != range.end() * 8; bx += 8) {
            for (int64_t by = 0; by < box.ny; by += 8) {
                if (!FindBricks(box, read_words, bx, by, acc, any)) continue;
                for (int64_t bz = 0; bz < box.nz; bz += 8) {
                    if (!any[bz >> 3]) continue;
                    GatherBrick(box, occupied_bytes, bx, by, bz, occ);
                    uint64_t any_free = 0, any_occ = 0;
                    std::memset(fre, 0, sizeof(fre));
                    for (const uint8_t* local : locals) {
                        GatherBrick(box, local, bx, by, bz, tmp);
                        for (int w = 0; w < 8; ++w) fre[w] |= tmp[w];
                    }
                    for (int w = 0; w < 8; ++w) {
                        fre[w] &= ~occ[w];
                        any_free |= fre[w];
                        any_occ |= occ[w];
                    }
                    const openvdb::Coord origin =
                        box.lo + openvdb::Coord(static_cast<int32_t>(bx), static_cast<int32_t>(by),
                                                static_cast<int32_t>(bz));
                    const auto emit = [&origin](const uint64_t* words, openvdb::MaskTree& out) {
                        auto* leaf = new MaskLeaf(origin);
                        for (int w = 0; w < 8; ++w) {
                            leaf->getValueMask().template getWord<uint64_t>(w) = words[w];
                        }
                        out.addLeaf(leaf);  // the tree owns it
                    };
                    if (any_free) emit(fre, my_free);
                    if (any_occ) emit(occ, my_occ);
                    if (crossed && any_free) {
                        // Free and outside every hit ray's margin.
                        std::memcpy(cro, fre, sizeof(cro));
                        for (const uint8_t* local : near_locals) {
                            GatherBrick(box, local, bx, by, bz, tmp);
                            for (int w = 0; w < 8; ++w) cro[w] &= ~tmp[w];
                        }
                        uint64_t any_crossed = 0;
                        for (int w = 0; w < 8; ++w) any_crossed |= cro[w];
                        if (any_crossed) emit(cro, my_crossed);
                    }
                }
                for (uint64_t* bits : all_words) ClearColumn(box, bits, bx, by);
            }
        }
    });
    bitmaps.clean = true;
    ScanMasks masks;
    for (auto& tree : free_trees) masks.free->merge(tree, openvdb::MERGE_NODES);
    for (auto& tree : occ_trees) masks.occupied->merge(tree, openvdb::MERGE_NODES);
    if (crossed) {
        masks.crossed = std::make_shared<openvdb::MaskTree>();
        for (auto& tree : crossed_trees) masks.crossed->merge(tree, openvdb::MERGE_NODES);
    }
    return masks;
}

// Bounded-memory path for scans whose box is too large for a bitmap.
ScanMasks MarkSparse(const PreparedScan& scan, const NearEndMargin& margin) {
    const VoxelBox& box = scan.box;
    struct Trees {
        openvdb::MaskTree free, near;
    };
    tbb::enumerable_thread_specific<Trees> trees;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, RayCount(scan), kRayGrain),
                      [&](const tbb::blocked_range<size_t>& range) {
                          Trees& mine = trees.local();
                          openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(mine.free);
                          const auto mark = [&](int64_t pos) { acc.setValueOn(box.CoordOf(pos)); };
                          if (margin.metres <= 0.0) return TraceRays(scan, range, mark, nullptr);
                          openvdb::tree::ValueAccessor<openvdb::MaskTree> near(mine.near);
                          TraceRays(scan, range, mark, nullptr, margin,
                                    [&](int64_t pos) { near.setValueOn(box.CoordOf(pos)); });
                      });
    ScanMasks masks;
    for (const Trees& t : trees) masks.free->topologyUnion(t.free);
    openvdb::tree::ValueAccessor<openvdb::MaskTree> acc(*masks.occupied);
    for (const int64_t pos : scan.endpoint_pos) acc.setValueOn(box.CoordOf(pos));
    masks.free->topologyDifference(*masks.occupied);
    if (margin.metres > 0.0) {
        masks.crossed = std::make_shared<openvdb::MaskTree>(*masks.free);
        for (const Trees& t : trees) masks.crossed->topologyDifference(t.near);
    }
    return masks;
}

}  // namespace

void RequireSparseMarkingFits(const PreparedScan& scan, const IntegrationConfig& config) {
    // What a VDB tree pays for the voxels rays cross: a leaf per 8^3 block (~2 kB for a float
    // grid, plus the marking masks) and an internal node per 128^3 block (16^3 child slots,
    // ~33 kB, in each of ~8 trees). At 1 cm a leaf is 8 cm and a node 1.28 m wide: long rays
    // through fresh space cost far more than the voxels suggest. Bound the cost before marking:
    // first without sharing between rays (cheap), then, only if that bound is over budget, by
    // counting the blocks the rays enter (sampled every half leaf, stopping at the budget).
    constexpr double kBytesPerLeaf = 2.5 * 1024.0;
    constexpr double kBytesPerNode = 8.0 * 33.0 * 1024.0;
    const double budget = static_cast<double>(config.max_update_bytes);
    const double s = scan.voxel_size;
    const auto cost = [&](double leaves, double nodes) {
        return leaves * kBytesPerLeaf + nodes * kBytesPerNode;
    };
    double leaves_bound = 0.0, nodes_bound = 0.0;
    for (size_t i = 0; i < scan.ends.size(); ++i) {
        if (scan.kinds[i] == PointKind::kDropped) continue;
        const double length = (scan.ends[i] - scan.origin).norm() / s;  // voxels
        leaves_bound += length / 8.0 + 2.0;
        nodes_bound += length / 128.0 + 2.0;
    }
    if (cost(leaves_bound, nodes_bound) <= budget) return;

    std::unordered_set<uint64_t> leaves, nodes;
    const auto key = [&](const Eigen::Vector3d& p, int shift) {
        const auto b = [&](double v) {
            return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / s)) >> shift) &
                   0x1fffff;
        };
        return b(p.x()) << 42 | b(p.y()) << 21 | b(p.z());
    };
    const double step = 4.0 * s;  // half a leaf
    for (size_t i = 0; i < scan.ends.size(); ++i) {
        if (scan.kinds[i] == PointKind::kDropped) continue;
        const Eigen::Vector3d d = scan.ends[i] - scan.origin;
        const double length = d.norm();
        for (double t = 0.0;; t = std::min(length, t + step)) {
            const Eigen::Vector3d p = scan.origin + (length > 0.0 ? t / length : 0.0) * d;
            leaves.insert(key(p, 3));
            nodes.insert(key(p, 7));
            if (t >= length) break;
        }
        const double bytes =
            cost(static_cast<double>(leaves.size()), static_cast<double>(nodes.size()));
        if (bytes > budget) {
            char text[320];
            std::snprintf(text, sizeof(text),
                          "this scan's rays cross over %zu leaves (8^3 voxels) at %.3g m: more "
                          "than %.1f GB of tree nodes, the most one scan may add: use a larger "
                          "voxel size or a shorter max range",
                          leaves.size(), s, budget / 1e9);
            throw RefusedError(text);
        }
    }
}

ScanMasks MarkScan(const PreparedScan& scan, const IntegrationConfig& config, Bitmaps& bitmaps) {
    const NearEndMargin margin{config.crossed_margin_m, config.crossed_margin_fraction};
    if (static_cast<uint64_t>(scan.box.size() / 8) <= config.dense_scratch_limit_bytes) {
        return MarkDense(scan, config.wide_walk && WideWalkAvailable(), margin, bitmaps);
    }
    // Only a scan too large for the dense scratch can be too large for memory.
    RequireSparseMarkingFits(scan, config);
    return MarkSparse(scan, margin);
}

}  // namespace strata::integration::detail
