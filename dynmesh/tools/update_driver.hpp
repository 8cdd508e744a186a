// dynmesh/tools/update_driver.hpp — the single-point update sequence of `stability` and `demo`.
//
// Purpose: drives a DynamicQuadtree<d> or a DynamicMesh (any `Structure` with points(),
// insert(p) -> PointId, erase(id), last_update() and box()) through alternating updates, one
// propagation each:
// even steps delete a present point chosen uniformly (Rng::below), odd steps insert the
// next point of an insertion pool drawn from the same distribution as the initial points.
// A pool point the tree rejects (outside the box, a duplicate, closer than the resolution
// to a present point: InputError) is skipped; when the pool runs dry, deleted points are
// reinserted in deletion order. With fewer than two points present a deletion becomes an
// insertion, so the spread stays defined.
//
// It also keeps log2(L/s) of the present points exact after every step (s = closest-pair
// distance), by reporting each update to a SpreadTracker (spread_tracker.hpp).
//
// Invariants: present() holds exactly the tree's points with their ids; spread_s() equals
// closest_pair_distance(present points).
// Complexity: step() is one propagation plus O(n) for the spread bookkeeping (untimed).
// Paper: Acar & Hudson, Section 1 (spread L/s), Section 4 (single-point updates).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "dynmesh/distributions.hpp"
#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/io.hpp"
#include "spread_tracker.hpp"

namespace dynmesh::tool {

template <std::size_t d, class Structure = DynamicQuadtree<d>>
class UpdateDriver {
 public:
  struct Step {
    EditOp op;
    UpdateStats stats;  // the structure's last_update() of this step
    double log2_spread;
  };

  /// Starts from the tree's current points; `pool` supplies the insertions, in order.
  UpdateDriver(Structure& tree, std::vector<Point<d>> pool, std::uint64_t seed)
      : tree_(tree), pool_(std::move(pool)), spread_(tree_.points(), tree_.box().side),
        rng_(seed ^ 0x7570'6461'7465'7321ULL) {}

  Step step() {
    const bool do_delete = (count_++ % 2 == 0) && spread_.present().size() > 2;
    Step out{do_delete ? EditOp::Delete : EditOp::Insert, {}, 0.0};
    if (do_delete)
      erase_one();
    else
      insert_one();
    out.stats = tree_.last_update();
    out.log2_spread = log2_spread();
    return out;
  }

  /// log2(L / s) of the present points (+inf if s = 0, −inf with fewer than two points).
  double log2_spread() const { return spread_.log2_spread(); }
  double spread_s() const noexcept { return spread_.spread_s(); }
  const std::vector<std::pair<PointId, Point<d>>>& present() const noexcept { return spread_.present(); }
  std::vector<Point<d>> coordinates() const { return spread_.coordinates(); }

 private:
  void erase_one() {
    const auto k = static_cast<std::size_t>(rng_.below(spread_.present().size()));
    const auto [id, p] = spread_.present()[k];
    tree_.erase(id);
    spread_.erased_at(k);
    deleted_.push_back(p);
  }

  void insert_one() {
    for (;;) {
      Point<d> p;
      if (next_pool_ < pool_.size()) {
        p = pool_[next_pool_++];
      } else if (!deleted_.empty()) {
        p = deleted_.front();
        deleted_.pop_front();
      } else {
        throw InputError(InputError::Kind::Empty, "no point left to insert (the insertion pool is exhausted)");
      }
      try {
        spread_.inserted(tree_.insert(p), p);
        return;
      } catch (const InputError&) {
        // Outside the box, a duplicate or too close: this pool point is unusable; the tree
        // is unchanged (failure atomicity), so try the next one.
      }
    }
  }

  Structure& tree_;
  std::vector<Point<d>> pool_;
  std::size_t next_pool_ = 0;
  std::deque<Point<d>> deleted_;
  SpreadTracker<d> spread_;
  Rng rng_;
  std::size_t count_ = 0;
};

}  // namespace dynmesh::tool
