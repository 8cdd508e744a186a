// tests/fuzz/differential.hpp — the differential driver of the dynamic fuzz targets: fuzz
// bytes become a run of insert, erase and batch (apply) operations on a self-adjusting
// structure, each checked against the expected point set and a from-scratch static twin.
//
// Purpose: one driver for DynamicQuadtree<2>, <3> (fuzz_dynamic_quadtree) and DynamicMesh
// (fuzz_dynamic_mesh). The driver keeps the expected state itself: the present points with
// their ids, in input-list order, and the next id. It predicts each operation's outcome from
// the contract alone (dynamic_quadtree.hpp, docs/FORMATS.md): an insertion is refused with
// NotFinite, OutsideBox, or whatever kind the static twin refuses the set with the point
// added; an erasure is refused with NotFinite, OutsideBox or Absent unless a present point
// equals the coordinates (or has the id); a batch applies its edits in order against the
// state so far, and is refused as a whole with the first refused edit's kind and index.
// Then:
//   * a refused operation must throw InputError of the predicted kind and leave everything
//     as it was: the trace's size and whatever else Traits::snapshot takes, and the points,
//     ids and result, which are checked against the expected state as after an update;
//   * an accepted one must return the predicted ids, leave the expected points (bit for
//     bit, in order) and the static twin's result (Traits::compare), and pass
//     check_invariants().
// The construction is checked the same way, except that only "refused or not" is compared
// (the static twin may see a different one of several bad points first).
//
// Traits (a class with a default constructor) provides, for dimension d:
//   using Subject;  using Oracle;  using Snapshot;
//   Subject make(const Box<d>&, std::span<const Point<d>>);   // the dynamic structure
//   Oracle oracle(const Box<d>&, std::span<const Point<d>>);  // the static twin; throws InputError
//   std::size_t compare(const Subject&, const Oracle&, std::span<const Point<d>>,
//                       const Point<d>& probe, bool updated);
//       // updated: an accepted insert, erase or batch just ran; returns the size of what it
//       // compared (leaves, triangles), the unit of the work budget
//   Snapshot snapshot(const Subject&);  bool same(const Snapshot&, const Snapshot&);
//                                      // cheap: what compare() does not see (trace size, ...)
//   std::string describe(const Subject&);  // its size, for the trace
//   static constexpr std::size_t kMaxWork;   // the work budget of a run, in compare()'s unit
// compare() runs after construction and every accepted operation, in order, so a Traits may
// keep state between calls (the mesh's change feed).
// With DYNMESH_FUZZ_TRACE set in the environment, every step is printed on stderr, so that a
// finding can be read as the run of operations it is (run the target on the saved input).
// Bounds: at most kMaxOps operations, 16 initial points, batches of up to 8 edits, and
// insertions turn into erasures once kMaxPoints are present; and the run stops once the
// compared sizes add up to Traits::kMaxWork (points a few ulps apart make trees 50 levels
// deep, whose checks cost a hundred times more), so every input runs fast.
// Complexity: per operation at most one static build (none when the set is unchanged) and
// one check_invariants, O(n lg n + |T|).
// Paper: none (the contracts: docs/DESIGN.md, "The quadtree contract" and "The mesh contract (2D)").
#pragma once

#include "fuzz_support.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dynmesh/dynamic_quadtree.hpp"
#include "dynmesh/edit.hpp"

namespace dynmesh_fuzz {

inline constexpr std::size_t kMaxOps = 64;
inline constexpr std::size_t kMaxPoints = 64;
inline constexpr std::size_t kMaxInitial = 16;
inline constexpr std::size_t kMaxBatch = 8;

using Kind = InputError::Kind;

template <std::size_t d, class Traits>
class Differential {
 public:
  using Subject = typename Traits::Subject;
  using Oracle = typename Traits::Oracle;

  explicit Differential(FuzzedDataProvider& in) : in_(in), source_(in, Box<d>{}) {}

  void run() {
    Box<d> box = PointSource<d>::decode_box(in_);
    trace(std::to_string(d) + "D, box origin " + to_string<d>(box.origin) + " side " + format_exact(box.side));
    const bool derived = in_.ConsumeBool();  // the box the commands derive from the initial points
    source_.set_box(box);
    std::vector<Point<d>> initial;
    for (std::size_t k = in_.ConsumeIntegralInRange<std::size_t>(0, kMaxInitial); k-- > 0;)
      initial.push_back(source_.next(initial));
    known_ = initial;
    if (derived) {
      try {
        box = derive_box<d>(initial);
      } catch (const InputError&) {
        return;  // no points, a NaN, or coordinates too large for a box: nothing to build
      }
      source_.set_box(box);
    }
    try {
      validate_box(box);
    } catch (const InputError&) {
      bool refused = false;
      try {
        (void)traits_.make(box, initial);
      } catch (const InputError&) {
        refused = true;
      }
      check(refused, "the constructor accepted a box that validate_box refuses");
      return;
    }
    box_ = box;
    if (derived) trace("derived box origin " + to_string<d>(box.origin) + " side " + format_exact(box.side));
    trace("construct from " + points_text(initial));
    std::optional<Subject> subject = construct(initial);
    if (!subject) return;  // a box the structure refuses even without points
    Subject& s = *subject;

    for (std::size_t op = 0; op < kMaxOps && in_.remaining_bytes() > 0 && work_ < Traits::kMaxWork; ++op) {
      switch (in_.ConsumeIntegralInRange<int>(0, 9)) {
        case 0:
        case 1:
        case 2: insert(s, next_insertion()); break;
        case 3:
        case 4: erase_point(s, next_erasure()); break;
        case 5: erase_id(s); break;
        case 6:
        case 7: batch(s); break;
        case 8:
          trace("compact");
          s.compact();
          unchanged(s);
          break;
        default:
          trace("probe");
          unchanged(s);
          break;
      }
    }
  }

 private:
  // ------------------------------------------------------------------ construction
  std::optional<Subject> construct(const std::vector<Point<d>>& initial) {
    std::optional<Oracle> want;
    try {
      want.emplace(traits_.oracle(box_, initial));
    } catch (const InputError&) {
    }
    std::optional<Subject> got;
    try {
      got.emplace(traits_.make(box_, initial));
    } catch (const InputError& e) {
      if (want) fail(std::string("the constructor refused what the static twin accepts: ") + e.what());
    }
    if (!got) {
      // Refused by both: go on from an empty set in the same box, if both accept that.
      std::optional<Oracle> empty;
      try {
        empty.emplace(traits_.oracle(box_, {}));
      } catch (const InputError&) {
      }
      try {
        got.emplace(traits_.make(box_, {}));
      } catch (const InputError& e) {
        if (empty) fail(std::string("the constructor refused a box that the static twin accepts: ") + e.what());
        return got;
      }
      if (!empty) fail("the constructor accepted a box that the static twin refuses");
      accepted(*got, false, std::move(empty));
      return got;
    }
    if (!want) fail("the constructor accepted a point set that the static twin refuses");
    for (std::size_t i = 0; i < initial.size(); ++i) present_.emplace_back(next_id_++, initial[i]);
    accepted(*got, false, std::move(want));
    return got;
  }

  // ------------------------------------------------------------------ decoding operations
  Point<d> next_point() {
    Point<d> p = source_.next(known_);
    if (known_.size() < 4 * kMaxPoints) known_.push_back(p);
    return p;
  }
  /// Mostly a present point, so that erasures succeed often.
  Point<d> next_erasure() {
    if (!present_.empty() && in_.ConsumeIntegralInRange<int>(0, 3) != 0)
      return present_[in_.ConsumeIntegralInRange<std::size_t>(0, present_.size() - 1)].second;
    return next_point();
  }
  Point<d> next_insertion() { return next_point(); }

  // ------------------------------------------------------------------ the expected outcome
  std::vector<Point<d>> coordinates(const std::vector<std::pair<PointId, Point<d>>>& set) const {
    std::vector<Point<d>> out;
    out.reserve(set.size());
    for (const auto& entry : set) out.push_back(entry.second);
    return out;
  }
  static std::optional<Kind> location_refusal(const Box<d>& box, const Point<d>& p) {
    if (!finite<d>(p)) return Kind::NotFinite;
    if (!try_locate<d>(box, p)) return Kind::OutsideBox;
    return std::nullopt;
  }
  /// Why inserting p into `set` is refused, if it is; `twin` gets the static twin of the
  /// set with p when it is not.
  std::optional<Kind> insert_refusal(const std::vector<std::pair<PointId, Point<d>>>& set, const Point<d>& p,
                                     std::optional<Oracle>* twin = nullptr) const {
    if (auto kind = location_refusal(box_, p)) return kind;
    std::vector<Point<d>> pts = coordinates(set);
    pts.push_back(p);
    try {
      Oracle o = traits_.oracle(box_, pts);
      if (twin) twin->emplace(std::move(o));
    } catch (const InputError& e) {
      return e.kind();
    }
    return std::nullopt;
  }
  /// Why erasing p from `set` is refused, if it is; otherwise the index of the point erased.
  static std::optional<Kind> erase_refusal(const Box<d>& box, const std::vector<std::pair<PointId, Point<d>>>& set,
                                           const Point<d>& p, std::size_t& index) {
    if (auto kind = location_refusal(box, p)) return kind;
    for (index = 0; index < set.size(); ++index)
      if (set[index].second == p) return std::nullopt;  // IEEE equality, as "exactly these values"
    return Kind::Absent;
  }

  // ------------------------------------------------------------------ operations
  void insert(Subject& s, const Point<d>& p) {
    if (present_.size() >= kMaxPoints) return erase_point(s, next_erasure());
    std::optional<Oracle> twin;
    const std::optional<Kind> refusal = insert_refusal(present_, p, &twin);
    trace("insert " + to_string<d>(p));
    const auto before = traits_.snapshot(s);
    PointId id = 0;
    try {
      id = s.insert(p);
    } catch (const InputError& e) {
      refused(s, before, e, refusal, std::nullopt, "insert");
      return;
    }
    if (refusal) fail(std::string("insert accepted a point the contract refuses with ") + kind_name(*refusal));
    check(id == next_id_, "insert returned an unexpected id");
    present_.emplace_back(next_id_++, p);
    accepted(s, true, std::move(twin));
  }

  void erase_point(Subject& s, const Point<d>& p) {
    std::size_t index = 0;
    const std::optional<Kind> refusal = erase_refusal(box_, present_, p, index);
    trace("erase " + to_string<d>(p));
    const auto before = traits_.snapshot(s);
    try {
      s.erase(p);
    } catch (const InputError& e) {
      refused(s, before, e, refusal, std::nullopt, "erase(point)");
      return;
    }
    if (refusal) fail(std::string("erase(point) accepted what the contract refuses with ") + kind_name(*refusal));
    present_.erase(present_.begin() + static_cast<std::ptrdiff_t>(index));
    accepted(s, true);
  }

  void erase_id(Subject& s) {
    PointId id;
    if (!present_.empty() && in_.ConsumeBool())
      id = present_[in_.ConsumeIntegralInRange<std::size_t>(0, present_.size() - 1)].first;
    else
      id = in_.ConsumeIntegralInRange<PointId>(0, next_id_ + 2);
    const auto it = std::find_if(present_.begin(), present_.end(), [&](const auto& e) { return e.first == id; });
    trace("erase id " + std::to_string(id));
    const auto before = traits_.snapshot(s);
    try {
      s.erase(id);
    } catch (const InputError& e) {
      refused(s, before, e, it == present_.end() ? std::optional<Kind>(Kind::Absent) : std::nullopt, std::nullopt,
              "erase(id)");
      return;
    }
    if (it == present_.end()) fail("erase(id) accepted an id that is not present");
    present_.erase(it);
    accepted(s, true);
  }

  void batch(Subject& s) {
    std::vector<Edit<d>> edits;
    for (std::size_t k = in_.ConsumeIntegralInRange<std::size_t>(0, kMaxBatch); k-- > 0;) {
      const bool add = in_.ConsumeBool() && present_.size() + edits.size() < kMaxPoints;
      edits.push_back(add ? Edit<d>{EditOp::Insert, next_insertion()} : Edit<d>{EditOp::Delete, next_erasure()});
    }
    // The expected outcome: the edits in order against the state so far.
    auto after = present_;
    PointId next = next_id_;
    std::vector<PointId> ids;
    std::optional<Kind> refusal;
    std::size_t failing = 0;
    for (std::size_t i = 0; i < edits.size() && !refusal; ++i) {
      const Edit<d>& e = edits[i];
      std::size_t index = 0;
      refusal = e.op == EditOp::Insert ? insert_refusal(after, e.point) : erase_refusal(box_, after, e.point, index);
      if (refusal) {
        failing = i;
      } else if (e.op == EditOp::Insert) {
        ids.push_back(next);
        after.emplace_back(next++, e.point);
      } else {
        after.erase(after.begin() + static_cast<std::ptrdiff_t>(index));
      }
    }
    if (tracing()) {
      std::string text = "apply";
      for (const Edit<d>& e : edits) text += (e.op == EditOp::Insert ? " +" : " -") + to_string<d>(e.point);
      trace(text);
    }
    const auto before = traits_.snapshot(s);
    std::vector<PointId> got;
    try {
      got = s.apply(edits);
    } catch (const InputError& e) {
      refused(s, before, e, refusal, failing, "apply");
      return;
    }
    if (refusal)
      fail("apply accepted a batch whose edit " + std::to_string(failing) + " the contract refuses with " +
           kind_name(*refusal));
    check(got == ids, "apply returned unexpected ids");
    present_ = std::move(after);
    next_id_ = next;
    accepted(s, true);
  }

  // ------------------------------------------------------------------ checking
  void refused(const Subject& s, const typename Traits::Snapshot& before, const InputError& e,
               const std::optional<Kind>& want, const std::optional<std::size_t>& failing, const char* what) {
    trace(std::string("  refused: ") + kind_name(e.kind()) + ": " + e.what());
    if (!want) fail(std::string(what) + " refused what the contract accepts: " + e.what());
    if (e.kind() != *want)
      fail(std::string(what) + " refused with " + kind_name(e.kind()) + ", the contract says " + kind_name(*want) +
           ": " + e.what());
    if (failing && (e.point_indices().empty() || e.point_indices().back() != *failing))
      fail(std::string(what) + " did not name the failing edit " + std::to_string(*failing) + ": " + e.what());
    check(traits_.same(before, traits_.snapshot(s)), "a refused operation changed the trace");
    unchanged(s);
  }

  /// After an operation that changes nothing: compare with the last static twin again.
  void unchanged(const Subject& s) { accepted(s, false, std::move(last_)); }

  /// After the construction or an operation: compare with `twin`, the static twin of the
  /// expected points (built here if not given), and keep it for unchanged().
  void accepted(const Subject& s, bool updated, std::optional<Oracle> twin = std::nullopt) {
    const auto pts = coordinates(present_);
    const auto got = s.points();
    check(got.size() == present_.size() && s.size() == present_.size(), "the structure holds a different number of points");
    for (std::size_t i = 0; i < got.size(); ++i) {
      check(got[i].first == present_[i].first, "points(): an unexpected id or order");
      check(same_bits<d>(got[i].second, present_[i].second), "points(): coordinates differ from those inserted");
      check(s.contains(present_[i].first), "contains() misses a present id");
      check(s.find(present_[i].second) == std::optional<PointId>(present_[i].first), "find() misses a present point");
    }
    const Point<d> probe = next_point();
    if (!twin) {
      try {
        twin.emplace(traits_.oracle(box_, pts));
      } catch (const InputError& e) {
        fail(std::string("the static twin refuses the point set the structure accepted: ") + e.what());
      }
    }
    work_ += traits_.compare(s, *twin, pts, probe, updated);
    invariants(s);
    last_ = std::move(twin);
    trace("  now " + std::to_string(present_.size()) + " points, " + traits_.describe(s));
  }

  static bool tracing() {
    static const bool on = std::getenv("DYNMESH_FUZZ_TRACE") != nullptr;
    return on;
  }
  static void trace(const std::string& text) {
    if (tracing()) std::fprintf(stderr, "%s\n", text.c_str());
  }
  static std::string points_text(const std::vector<Point<d>>& pts) {
    std::string text = std::to_string(pts.size()) + " points";
    if (!tracing()) return text;
    for (const Point<d>& p : pts) text += " " + to_string<d>(p);
    return text;
  }

  static void invariants(const Subject& s) {
    try {
      s.check_invariants();
    } catch (const std::exception& e) {
      fail(std::string("check_invariants: ") + e.what());
    }
  }

  FuzzedDataProvider& in_;
  PointSource<d> source_;
  Traits traits_{};
  Box<d> box_{};
  std::vector<std::pair<PointId, Point<d>>> present_;  // input-list order
  PointId next_id_ = 0;
  std::vector<Point<d>> known_;  // every point decoded so far (bounded), for near-collisions
  std::optional<Oracle> last_;   // the static twin of present_
  std::size_t work_ = 0;         // sizes compared so far
};

/// The change feed's contract over a run, for a mesh's Traits::compare: empty after the
/// construction; after an update, the simplices before it less its removed plus its added are
/// the simplices after it; without an update, nothing changed.
template <class Simplex>
class FeedReplay {
 public:
  template <class Change>
  void step(const std::vector<Simplex>& now, const Change& change, bool updated) {
    if (first_) {
      check(change.removed.empty() && change.added.empty(), "the feed is not empty after construction");
    } else if (updated) {
      std::vector<Simplex> replay = previous_;
      check(apply_change(replay, change) && replay == now, "the change feed does not replay the update");
    } else {
      check(now == previous_, "the mesh changed without an update");
    }
    first_ = false;
    previous_ = now;
  }

 private:
  bool first_ = true;
  std::vector<Simplex> previous_;
};

}  // namespace dynmesh_fuzz
