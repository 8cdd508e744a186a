// sac/detail/intrusive_hash.hpp — chained hash table over trace records (memo and allocation
// tables).
//
// Purpose: find the memo entries and keyed allocations a re-execution may reuse. The records
// carry their own chain link (hnext) and know their hash through their ops, so
// the table is one bucket array. Lookups return every record of a bucket; the engine filters
// by ops, key and trace window.
// Invariants: every record is in bucket hash(record) & mask; size() counts them;
//             buckets.size() is a power of two >= size() / 2 (grows at load factor 2:
//             lookups happen only during re-execution, inserts on every keyed allocation).
// Complexity: insert O(1) amortized, erase O(chain), lookup O(chain).
// Paper: docs/DESIGN.md, "Memoization and keyed allocation".
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sac/errors.hpp"

namespace sac::detail {

template <class N>
class IntrusiveHash {
 public:
  template <class HashOf>
  void insert(N* n, std::size_t h, HashOf&& hash_of) {
    if (size_ + 1 > 2 * buckets_.size()) grow(hash_of);
    N*& b = buckets_[h & (buckets_.size() - 1)];
    n->hnext = b;
    b = n;
    ++size_;
  }

  /// Inserts with no growth check: only after reserve() made room.
  void insert_reserved(N* n, std::size_t h) {
    N*& b = buckets_[h & (buckets_.size() - 1)];
    n->hnext = b;
    b = n;
    ++size_;
  }

  /// Grows (once) so that `count` records fit without further growth.
  template <class HashOf>
  void reserve(std::size_t count, HashOf&& hash_of) {
    std::size_t want = buckets_.empty() ? 64 : buckets_.size();
    while (count > 2 * want) want *= 2;
    if (want != buckets_.size()) rebucket(want, hash_of);
  }

  void erase(N* n, std::size_t h) {
    N** pp = &buckets_[h & (buckets_.size() - 1)];
    while (*pp != n) pp = &(*pp)->hnext;
    *pp = n->hnext;
    n->hnext = nullptr;
    --size_;
  }

  N* bucket(std::size_t h) const {
    return buckets_.empty() ? nullptr : buckets_[h & (buckets_.size() - 1)];
  }

  std::size_t size() const { return size_; }
  std::size_t memory_bytes() const { return buckets_.capacity() * sizeof(N*); }

  template <class HashOf, class Visit>
  void check_invariants(const char* name, HashOf&& hash_of, Visit&& visit) const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < buckets_.size(); ++i)
      for (N* x = buckets_[i]; x; x = x->hnext) {
        if ((hash_of(x) & (buckets_.size() - 1)) != i)
          throw InvariantError(std::string(name) + ": record in the wrong bucket");
        visit(x);
        ++n;
      }
    if (n != size_) throw InvariantError(std::string(name) + ": size mismatch");
  }

  template <class Visit>
  void for_each(Visit&& visit) const {
    for (N* b : buckets_)
      for (N* x = b; x;) {
        N* nx = x->hnext;
        visit(x);
        x = nx;
      }
  }

 private:
  template <class HashOf>
  void grow(HashOf& hash_of) { rebucket(buckets_.empty() ? 64 : buckets_.size() * 2, hash_of); }

  template <class HashOf>
  void rebucket(std::size_t nbuckets, HashOf& hash_of) {
    // Records are long out of cache when the table grows; prefetching the chains a few
    // buckets ahead overlaps those misses.
    constexpr std::size_t kAhead = 16;
    std::vector<N*> old;
    old.swap(buckets_);
    buckets_.assign(nbuckets, nullptr);
    const std::size_t mask = buckets_.size() - 1;
    for (std::size_t i = 0; i < old.size(); ++i) {
      if (i + kAhead < old.size() && old[i + kAhead]) __builtin_prefetch(old[i + kAhead]);
      for (N* x = old[i]; x;) {
        N* nx = x->hnext;
        if (nx) __builtin_prefetch(nx);
        N*& nb = buckets_[hash_of(x) & mask];
        x->hnext = nb;
        nb = x;
        x = nx;
      }
    }
  }

  std::vector<N*> buckets_;
  std::size_t size_ = 0;
};

}  // namespace sac::detail
