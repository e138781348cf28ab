#include "strata/integration/UpdateParts.hpp"

#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>

#include "strata/core/Error.hpp"

namespace strata::integration {
namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;
constexpr uint32_t kMagic = 0x32555453;  // "STU2": strata update, version 2 (the crossed space)
constexpr size_t kMaskWords = MaskLeaf::NodeMaskType::WORD_COUNT;
// A leaf's record: its origin (three int32) and its mask words, packed.
constexpr size_t kLeafBytes = 3 * sizeof(int32_t) + kMaskWords * sizeof(uint64_t);
// An endpoint group's record: voxel, points, class, offset sum.
constexpr size_t kGroupBytes = 4 * sizeof(int32_t) + 1 + 3 * sizeof(double);

openvdb::MaskTree::Ptr SelectLeaves(const openvdb::MaskTree& tree, const LeafFilter& keep) {
    auto out = std::make_shared<openvdb::MaskTree>();
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        if (keep(leaf->origin())) out->addLeaf(new MaskLeaf(*leaf));
    }
    return out;
}

openvdb::Coord LeafOrigin(const openvdb::Coord& ijk) {
    return {ijk.x() & ~7, ijk.y() & ~7, ijk.z() & ~7};
}

// Appends trivially copyable values in the machine's byte order (strata runs on little-endian
// x86-64 and ARM64 only; the magic number refuses anything else).
class UpdateWriter {
public:
    explicit UpdateWriter(size_t reserve) { bytes_.reserve(reserve); }

    template <typename T>
    void Put(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
    }
    // A count written once its records are: PutCount(), the records, SetCount(at, n).
    size_t PutCount() {
        Put(uint64_t{0});
        return bytes_.size() - sizeof(uint64_t);
    }
    void SetCount(size_t at, uint64_t count) {
        std::memcpy(bytes_.data() + at, &count, sizeof(count));
    }
    // The leaves `keep` accepts (every leaf without a filter): their count, then each one's
    // origin and mask words, appended as one record.
    void PutTree(const openvdb::MaskTree& tree, const LeafFilter& keep) {
        const size_t count_at = PutCount();
        uint64_t count = 0;
        char record[kLeafBytes];
        for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
            const openvdb::Coord& o = leaf->origin();
            if (keep && !keep(o)) continue;
            const int32_t origin[3] = {o.x(), o.y(), o.z()};
            std::memcpy(record, origin, sizeof(origin));
            const auto& mask = leaf->getValueMask();
            for (size_t w = 0; w < kMaskWords; ++w) {
                const uint64_t word = mask.getWord<uint64_t>(w);
                std::memcpy(record + sizeof(origin) + w * sizeof(word), &word, sizeof(word));
            }
            bytes_.append(record, kLeafBytes);
            ++count;
        }
        SetCount(count_at, count);
    }
    std::string Take() { return std::move(bytes_); }

private:
    std::string bytes_;
};

class UpdateReader {
public:
    UpdateReader(std::string_view bytes, const std::string& what) : bytes_(bytes), what_(what) {}

    template <typename T>
    T Get() {
        if (bytes_.size() - pos_ < sizeof(T)) Fail("truncated");
        T value;
        std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        return value;
    }
    void GetBytes(void* into, size_t n) {
        if (bytes_.size() - pos_ < n) Fail("truncated");
        std::memcpy(into, bytes_.data() + pos_, n);
        pos_ += n;
    }
    // Three reads in order (the arguments of one constructor call are evaluated in any order).
    openvdb::Coord GetCoord() {
        const auto x = Get<int32_t>();
        const auto y = Get<int32_t>();
        const auto z = Get<int32_t>();
        return {x, y, z};
    }
    // A count of records of `record_bytes` each that the remaining bytes can hold.
    size_t Count(size_t record_bytes) {
        const auto n = Get<uint64_t>();
        if (n > (bytes_.size() - pos_) / record_bytes) Fail("truncated");
        return static_cast<size_t>(n);
    }
    openvdb::MaskTree::Ptr GetTree() {
        auto tree = std::make_shared<openvdb::MaskTree>();
        openvdb::tree::ValueAccessor<openvdb::MaskTree> leaves(*tree);
        const size_t n = Count(kLeafBytes);
        for (size_t i = 0; i < n; ++i) {
            const openvdb::Coord origin = GetCoord();
            if (LeafOrigin(origin) != origin) Fail("a leaf origin is not a multiple of 8");
            if (leaves.probeConstLeaf(origin)) Fail("a leaf appears twice");
            auto leaf = std::make_unique<MaskLeaf>(origin, false);
            GetBytes(&leaf->getValueMask().getWord<uint64_t>(0), kMaskWords * sizeof(uint64_t));
            leaves.addLeaf(leaf.release());
        }
        return tree;
    }
    void End() const {
        if (pos_ != bytes_.size()) Fail("trailing bytes");
    }
    [[noreturn]] void Fail(const char* problem) const {
        throw FormatError(what_ + ": not a scan update (" + problem + ")");
    }

private:
    std::string_view bytes_;
    const std::string& what_;
    size_t pos_ = 0;
};

}  // namespace

bool AllLeaves(const ScanUpdate& update, const LeafFilter& keep) {
    for (const auto* tree : {update.free.get(), update.occupied.get(), update.crossed.get()}) {
        if (!tree) continue;
        for (auto leaf = tree->cbeginLeaf(); leaf; ++leaf) {
            if (!keep(leaf->origin())) return false;
        }
    }
    openvdb::Coord last(std::numeric_limits<int32_t>::max());
    for (const EndpointGroup& g : update.endpoints) {
        const openvdb::Coord origin = LeafOrigin(g.ijk);
        if (origin != last && !keep(origin)) return false;
        last = origin;
    }
    return true;
}

ScanUpdate SelectUpdate(const ScanUpdate& update, const LeafFilter& keep) {
    ScanUpdate part;
    part.free = SelectLeaves(*update.free, keep);
    part.occupied = SelectLeaves(*update.occupied, keep);
    if (update.crossed) part.crossed = SelectLeaves(*update.crossed, keep);
    // Groups come sorted by voxel, so the voxels of one leaf mostly follow each other.
    openvdb::Coord last(std::numeric_limits<int32_t>::max());
    bool kept = false;
    for (const EndpointGroup& g : update.endpoints) {
        const openvdb::Coord origin = LeafOrigin(g.ijk);
        if (origin != last) {
            last = origin;
            kept = keep(origin);
        }
        if (kept) part.endpoints.push_back(g);
    }
    part.points = update.points;
    part.dropped = update.dropped;
    part.clipped = update.clipped;
    return part;
}

std::string EncodeUpdate(const ScanUpdate& update, const LeafFilter& keep) {
    const size_t leaves = update.free->leafCount() + update.occupied->leafCount() +
                          (update.crossed ? update.crossed->leafCount() : 0);
    UpdateWriter w(sizeof(kMagic) + 6 * sizeof(uint64_t) + leaves * kLeafBytes +
                   update.endpoints.size() * kGroupBytes);
    w.Put(kMagic);
    w.Put(static_cast<uint64_t>(update.points));
    w.Put(static_cast<uint64_t>(update.dropped));
    w.Put(static_cast<uint64_t>(update.clipped));
    w.PutTree(*update.free, keep);
    w.PutTree(*update.occupied, keep);
    w.Put(static_cast<uint8_t>(update.crossed ? 1 : 0));
    if (update.crossed) w.PutTree(*update.crossed, keep);
    const size_t count_at = w.PutCount();
    uint64_t count = 0;
    // Groups come sorted by voxel, so the voxels of one leaf mostly follow each other.
    openvdb::Coord last(std::numeric_limits<int32_t>::max());
    bool kept = true;
    for (const EndpointGroup& g : update.endpoints) {
        if (keep) {
            const openvdb::Coord origin = LeafOrigin(g.ijk);
            if (origin != last) {
                last = origin;
                kept = keep(origin);
            }
        }
        if (!kept) continue;
        w.Put(g.ijk.x());
        w.Put(g.ijk.y());
        w.Put(g.ijk.z());
        w.Put(g.points);
        w.Put(static_cast<uint8_t>(g.label));
        w.Put(g.offset_sum.x());
        w.Put(g.offset_sum.y());
        w.Put(g.offset_sum.z());
        ++count;
    }
    w.SetCount(count_at, count);
    return w.Take();
}

ScanUpdate DecodeUpdate(std::string_view bytes, const std::string& what) {
    UpdateReader r(bytes, what);
    if (r.Get<uint32_t>() != kMagic) r.Fail("unknown version");
    ScanUpdate update;
    update.points = static_cast<size_t>(r.Get<uint64_t>());
    update.dropped = static_cast<size_t>(r.Get<uint64_t>());
    update.clipped = static_cast<size_t>(r.Get<uint64_t>());
    update.free = r.GetTree();
    update.occupied = r.GetTree();
    const auto has_crossed = r.Get<uint8_t>();
    if (has_crossed > 1) r.Fail("a bad flag");
    if (has_crossed == 1) update.crossed = r.GetTree();
    const size_t groups = r.Count(kGroupBytes);
    update.endpoints.resize(groups);
    for (EndpointGroup& g : update.endpoints) {
        g.ijk = r.GetCoord();
        g.points = r.Get<int32_t>();
        const auto label = r.Get<uint8_t>();
        if (label >= core::kNumClasses) r.Fail("a class out of range");
        if (g.points <= 0) r.Fail("an endpoint group without points");
        g.label = static_cast<core::SemanticClass>(label);
        g.offset_sum.x() = r.Get<double>();
        g.offset_sum.y() = r.Get<double>();
        g.offset_sum.z() = r.Get<double>();
    }
    r.End();
    return update;
}

}  // namespace strata::integration
