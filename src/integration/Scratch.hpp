#pragma once
// Private to the integrator: the memory one ScanWorkspace keeps from scan to scan (docs/
// integration.md, "Where the whole command's time goes"). Every buffer grows to the largest scan
// it served and is never given back, so that a drive's scans neither allocate nor fault in their
// working memory afresh.

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "RayMarking.hpp"
#include "strata/integration/Integrator.hpp"

namespace strata::integration::detail {

/// A bitmap over a scan's box in 64-bit words, all zero between two scans: the marking clears
/// every column of bricks it reads (MarkScan.cpp), so that the next scan need not clear it whole.
/// It keeps the size of the largest box it covered, at most IntegrationConfig's
/// dense_scratch_limit_bytes (64 MB): what each of the marking's threads holds during a scan
/// anyway (about 2 MB at 0.2 m and 50 m of range, 30 MB at 0.1 m).
struct Bitmap {
    std::vector<uint64_t> words;
    bool used = false;  ///< marked by the scan being integrated

    /// At least `n_words` words, every one zero.
    uint64_t* Zeroed(size_t n_words) {
        if (words.size() < n_words) words.resize(n_words, 0);
        return words.data();
    }
};

/// The marking's bitmaps: one per thread that walks rays, one for the endpoints, and one per
/// thread for the voxels near the rays' ends (when the crossed space is asked for).
struct Bitmaps {
    tbb::enumerable_thread_specific<Bitmap> free;
    Bitmap occupied;
    tbb::enumerable_thread_specific<Bitmap> near_end;
    /// False while a marking runs: one that threw may have left bits set, which the next one
    /// clears whole.
    bool clean = true;

    void ClearAll() {
        for (Bitmap& b : free) std::fill(b.words.begin(), b.words.end(), 0);
        for (Bitmap& b : near_end) std::fill(b.words.begin(), b.words.end(), 0);
        std::fill(occupied.words.begin(), occupied.words.end(), 0);
        clean = true;
    }
};

struct Scratch {
    std::vector<Eigen::Vector3d> points_map;  // the scan's points in the map frame
    PreparedScan prepared;
    std::vector<int64_t> pos;  // PrepareScan's scratch
    std::vector<uint64_t> keys, key_buffer;
    std::vector<uint32_t> points, point_buffer;
    Bitmaps bitmaps;
    UpdateSeconds seconds;
};

}  // namespace strata::integration::detail
