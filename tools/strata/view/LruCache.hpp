#pragma once
// Private to view: a thread-safe least-recently-used cache bounded by the bytes of its values.

#include <cstddef>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

namespace strata::view::detail {

template <typename Key, typename Value>
class LruCache {
public:
    explicit LruCache(size_t budget_bytes) : budget_(budget_bytes) {}

    /// The value, now the most recently used; null when absent.
    [[nodiscard]] std::shared_ptr<const Value> Get(const Key& key) {
        const std::lock_guard<std::mutex> lock(mutex_);
        const auto it = index_.find(key);
        if (it == index_.end()) return nullptr;
        order_.splice(order_.begin(), order_, it->second);
        return it->second->value;
    }

    /// Keeps `value` (costing `bytes`), dropping the least recently used entries beyond the
    /// budget; a value larger than the whole budget is not kept.
    void Put(const Key& key, std::shared_ptr<const Value> value, size_t bytes) {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (const auto it = index_.find(key); it != index_.end()) Erase(it);
        if (bytes > budget_) return;
        order_.push_front(Entry{key, std::move(value), bytes});
        index_.emplace(key, order_.begin());
        bytes_ += bytes;
        while (bytes_ > budget_) Erase(index_.find(order_.back().key));
    }

    [[nodiscard]] size_t bytes() const {
        const std::lock_guard<std::mutex> lock(mutex_);
        return bytes_;
    }

private:
    struct Entry {
        Key key;
        std::shared_ptr<const Value> value;
        size_t bytes = 0;
    };
    using Index = std::map<Key, typename std::list<Entry>::iterator>;

    void Erase(typename Index::iterator it) {
        bytes_ -= it->second->bytes;
        order_.erase(it->second);
        index_.erase(it);
    }

    size_t budget_;
    size_t bytes_ = 0;
    std::list<Entry> order_;  ///< most recently used first
    Index index_;
    mutable std::mutex mutex_;
};

}  // namespace strata::view::detail
