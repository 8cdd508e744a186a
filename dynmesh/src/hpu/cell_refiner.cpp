// cell_refiner.cpp — the hpu refinement on cell questions (see cell_refiner.hpp).
//
// Purpose: the static cell refiner: the twin's rules asked of a BucketTree through
// cell_questions.hpp, with an optional log of its steps (CellStep fingerprints).
// Invariants and Complexity: cell_refiner.hpp's.
// Paper: Acar & Hudson, Figure 5 and Appendix A; docs/HPU_ON_CELLS.md, "The questions, and
// why each answer is exact".
#include "hpu/cell_refiner.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <sac/splitmix64.hpp>

#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"
#include "dynmesh/quadtree_mesh.hpp"
#include "geometry/delaunay.hpp"  // perturbed_incircle: the twin's tie rule
#include "hpu/bucket_tree.hpp"
#include "hpu/hpu_geometry.hpp"
#include "dynmesh/detail/quadtree_mesh_rules.hpp"
#include "io/locate_points.hpp"

namespace dynmesh::detail {
namespace {

using Vid = std::uint32_t;
constexpr Vid kNone = 0xffff'ffffu;

// The step log's fingerprints (CellStep): sac::mix64 over the running hash times the golden
// gamma plus the next word, so that the order of the words counts.
std::uint64_t mix(std::uint64_t h, std::uint64_t x) noexcept { return sac::mix64(h * sac::kGoldenGamma + x); }
std::uint64_t mix(std::uint64_t h, const Point<2>& p) noexcept {
  return mix(mix(h, std::bit_cast<std::uint64_t>(p[0] + 0.0)), std::bit_cast<std::uint64_t>(p[1] + 0.0));
}

class CellRefiner {
 public:
  CellRefiner(const Box<2>& box, double min_angle_deg, std::size_t max_vertices, CellRefinement& out,
              const CellRefineOptions& options)
      : box_(box), tree_(box), questions_(box, min_angle_deg, tree_, Coords{&pts_}, kNone, out.questions),
        max_vertices_(max_vertices), out_(out), check_tree_(options.check_tree), log_steps_(options.log_steps),
        held_stars_(options.held_stars) {
    if (options.maintained_stars) ledger_ = std::make_unique<StarLedger>(box);
    const double lo[2] = {box.origin[0], box.origin[1]}, hi[2] = {box.origin[0] + box.side, box.origin[1] + box.side};
    // The corners first (vertices 0-3: the first entries' order puts them ahead).
    for (const Point<2>& c : {Point<2>{lo[0], lo[1]}, Point<2>{hi[0], lo[1]}, Point<2>{hi[0], hi[1]},
                              Point<2>{lo[0], hi[1]}})
      add(c);
  }

  void insert_inputs(std::span<const Point<2>> points) {
    for (const Point<2>& m : side_midpoints(box_, points)) {
      if (!questions_.find(m)) add(m);
      ++out_.stats.side_splits;
    }
    for (const Point<2>& p : points)
      if (!questions_.find(p)) add(p);
    first_inserted_ = static_cast<Vid>(pts_.size());  // the refinement's vertices from here
  }

  void refine() {
    for (const Vid v : first_entry_order(box_, pts_)) {
      step_begin();
      const int c = questions_.first_class(v, 0.0);
      step_end(CellStep::FirstClass, pts_[v], mix(0, pts_[v]), static_cast<std::uint64_t>(c));
      queues_[c].push_back({v, true});
    }
    run_rounds(queues_, batch_, pairs_, out_.stats.rounds, [&](const Entry& e, std::size_t, int j) { collect(e.v, j, e.birth); },
               [&](Vid p, Vid q, int j) { process(p, q, j); });
  }

  /// The Delaunay triangulation of all vertices, each triangle found from the local star of
  /// its (x, y)-smallest corner.
  std::vector<Triangle> triangles() {
    std::vector<Triangle> out;
    const std::size_t before = out_.questions.leaves_read;
    std::vector<std::array<Vid, 2>> mine;
    for (Vid v = 0; v < pts_.size(); ++v) {
      step_begin();
      std::uint64_t answer = 0;
      const std::size_t asks = out_.questions.neighbour_asks;
      bool all_held = false, whole_held = false;
      if (ledger_) {
        std::size_t needed = 0, unheld = 0;
        all_held = ledger_->all_held(v, StarLedger::kNoCap, needed, unheld, true);
        whole_held = ledger_->all_held(v, StarLedger::kNoCap, needed, unheld);
      }
      questions_.triangles_of(v, 0.0, mine);
      if (held_stars_) final_asks_.push_back(out_.questions.neighbour_asks - asks);
      if (ledger_) {
        MaintainedStarStats& m = out_.maintained;
        const std::size_t walk_asks = out_.questions.neighbour_asks - asks;
        ++m.finals;
        m.final_asks += walk_asks;
        if (all_held) ++m.answered_finals, m.answered_final_asks += walk_asks;
        else ledger_->walked_triangles(v, mine);
        if (whole_held) ++m.whole_finals, m.whole_final_asks += walk_asks;
      }
      for (const auto& [a, b] : mine) {
        out.push_back(canonical_triangle(pts_[v], pts_[a], pts_[b]));
        answer = mix(mix(answer, pts_[a]), pts_[b]);
      }
      step_end(CellStep::Final, pts_[v], mix(3, pts_[v]), answer);
    }
    std::sort(out.begin(), out.end());
    out_.questions.leaves_final += out_.questions.leaves_read - before;
    if (held_stars_) count_held_final(out);
    if (ledger_) ledger_->check_mesh(out);
    return out;
  }

  void check() const {
    tree_.check_invariants(pts_);
    if (ledger_) ledger_->check_invariants();
  }

 private:
  struct Entry {
    Vid v;
    bool birth;
  };
  struct Coords {
    const std::vector<Point<2>>* pts;
    const Point<2>& operator()(Vid v) const { return (*pts)[v]; }
  };

  // The step log (CellStep): what the cells hand out between step_begin and step_end.
  static std::uint64_t vertex_digest(const void* self, Vid v) {
    return mix(0x5eed, static_cast<const CellRefiner*>(self)->pts_[v]);
  }
  void step_begin() {
    if (!log_steps_) return;
    seen_ = 0;
    step_leaf_ids_.clear();
    tree_.watch(&seen_, &vertex_digest, this, &step_leaf_ids_);
  }
  void step_end(CellStep::Kind kind, const Point<2>& at, std::uint64_t key, std::uint64_t answer, int cls = 0) {
    if (!log_steps_) return;
    tree_.watch(nullptr, nullptr, nullptr);
    // A step reads a leaf once (a self-adjusting step keeps what it read): distinct leaves.
    std::sort(step_leaf_ids_.begin(), step_leaf_ids_.end());
    const auto distinct = std::unique(step_leaf_ids_.begin(), step_leaf_ids_.end()) - step_leaf_ids_.begin();
    out_.steps.push_back(CellStep{mix(mix(mix(key, kind), answer), seen_), static_cast<std::uint32_t>(distinct), kind,
                                  static_cast<std::int16_t>(std::clamp(cls, -30000, 30000)), at});
  }

  /// `near`: a vertex close to p (the ledger's locating hint), or kNone.
  Vid add(const Point<2>& p, Vid near = kNone) {
    const auto v = static_cast<Vid>(pts_.size());
    pts_.push_back(p);
    tree_.insert(v, p, pts_);
    if (ledger_) ledger_->add(v, p, near);
    if (pts_.size() > max_vertices_)
      throw InvariantError("dynmesh: hpu refinement did not terminate (over " + std::to_string(max_vertices_) +
                           " vertices)");
    if (check_tree_) tree_.check_invariants(pts_);
    return v;
  }

  /// Figure 5, line 7, for one vertex (the twin's collect).
  void collect(Vid v, int j, bool birth) {
    ++out_.stats.entries;
    step_begin();
    const std::size_t before = out_.questions.leaves_read;
    const std::size_t asks = out_.questions.neighbour_asks;
    bool all_held = false;
    if (ledger_)
      all_held = ledger_->all_held(v, j + kGoOnReach, out_.maintained.needed_triangles, out_.maintained.unheld_triangles);
    const bool go_on = questions_.collect(v, j, birth, local_pairs_);
    if (held_stars_) count_held(v, j, out_.questions.neighbour_asks - asks);
    if (ledger_) count_maintained(v, j, birth, all_held, out_.questions.neighbour_asks - asks);
    pairs_.insert(pairs_.end(), local_pairs_.begin(), local_pairs_.end());
    if (go_on) queues_[j + 1].push_back({v, false});
    std::uint64_t answer = go_on;
    for (const auto& [a, b] : local_pairs_) answer = mix(mix(answer, pts_[a]), pts_[b]);
    step_end(CellStep::Collect, pts_[v], mix(mix(mix(1, pts_[v]), static_cast<std::uint64_t>(j)), birth), answer, j);
    out_.questions.leaves_collect += out_.questions.leaves_read - before;
  }

  /// Figure 5, lines 10-14, for the ccw side of p→q (the twin's process).
  void process(Vid p, Vid q, int j) {
    step_begin();
    const std::size_t before = out_.questions.leaves_read;
    std::uint64_t answer = 0;
    for (;;) {
      const CellDecision<Vid> d = questions_.decide(p, q, j);
      if (d.kind == CellDecision<Vid>::Done) break;
      ++out_.stats.loose_pairs;
      if (d.kind == CellDecision<Vid>::Split) {
        for (const auto& s : d.splits) {
          split_side(s[0], s[1], j);
          answer = mix(answer, pts_.back());
        }
        continue;
      }
      const Vid rv = add(d.at, p);
      answer = mix(answer, d.at);
      ++out_.stats.off_centers;
      if (d.circumcentre) ++out_.stats.circumcentres;
      queues_[j].push_back({rv, true});
      break;
    }
    step_end(CellStep::Process, pts_[p], mix(mix(mix(2, pts_[p]), pts_[q]), static_cast<std::uint64_t>(j)), answer, j);
    out_.questions.leaves_process += out_.questions.leaves_read - before;
  }

  void split_side(Vid a, Vid b, int j) {
    const Point<2> mid = side_midpoint(pts_[a], pts_[b]);
    if (questions_.find(mid)) throw InvariantError("dynmesh: a box edge's midpoint is already a vertex");
    const Vid v = add(mid, a);
    ++out_.stats.side_splits;
    queues_[j].push_back({v, true});
  }

  // The maintained-stars count (star_ledger.hpp): a collect a held star replays makes no
  // walk; any other walks, and what it meets becomes held. The first collects of vertices
  // the refinement inserted are counted apart too.
  void count_maintained(Vid v, int j, bool birth, bool all_held, std::size_t asks) {
    MaintainedStarStats& m = out_.maintained;
    const bool whole = questions_.star_gap_ends() == 0;
    const bool closed = whole && !questions_.on_boundary(v);
    const bool replays = ledger_->replays(v, questions_.star(), whole, closed, j + kGoOnReach);
    ++m.collects;
    m.collect_asks += asks;
    if (all_held) ++m.answered, m.answered_asks += asks;
    if (replays) ++m.answered_design, m.answered_design_asks += asks;
    else ledger_->walked(v, questions_.star(), whole, closed, j + kGoOnReach);
    if (birth && v >= first_inserted_) {
      ++m.births;
      m.birth_asks += asks;
      if (replays) ++m.births_design, m.births_design_asks += asks;
    }
  }

  // The held-stars count: v's last collected walk, compared with the next one and with v's
  // neighbours in the final mesh.
  struct HeldStar {
    int j = 0;
    bool whole = false;
    bool ever_whole = false;  // an earlier walk was whole
    std::vector<Vid> star;    // sorted
    std::vector<std::pair<Vid, Vid>> tris;  // the walk's triangles, sorted
  };
  void count_held(Vid v, int j, std::size_t asks) {
    CellQuestionStats& q = out_.questions;
    ++q.collects;
    q.collect_asks += asks;
    const std::vector<Vid>& walked = questions_.star();
    std::vector<Vid> now = walked;
    std::sort(now.begin(), now.end());
    const bool whole = questions_.star_gap_ends() == 0;
    HeldStar& h = held_[v];
    // The walk's triangles as (ccw neighbour pairs): consecutive in star(), and around the
    // end for an interior vertex's whole star.
    std::vector<std::pair<Vid, Vid>> tris;
    for (std::size_t i = 0; i + 1 < walked.size(); ++i) tris.emplace_back(walked[i], walked[i + 1]);
    if (whole && !questions_.on_boundary(v) && walked.size() > 2) tris.emplace_back(walked.back(), walked.front());
    std::sort(tris.begin(), tris.end());
    q.walk_triangles += tris.size();
    for (const auto& t : tris)
      if (std::binary_search(h.tris.begin(), h.tris.end(), t)) ++q.repeated_triangles;
    if (!h.star.empty() && h.star == now && (h.whole ? whole : !whole && h.j >= j)) {
      ++q.held_collects;
      q.held_asks += asks;
    }
    if (h.whole || h.ever_whole) {
      ++q.kept_collects;
      q.kept_asks += asks;
    }
    const bool ever = h.whole || h.ever_whole;
    h = HeldStar{j, whole, ever, std::move(now), std::move(tris)};
  }
  void count_held_final(const std::vector<Triangle>& tris) {
    std::map<std::pair<double, double>, Vid> id;
    for (Vid v = 0; v < pts_.size(); ++v) id[{pts_[v][0], pts_[v][1]}] = v;
    std::vector<std::vector<Vid>> nb(pts_.size());
    for (const Triangle& t : tris)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          if (a != b) nb[id.at({t.v[a][0], t.v[a][1]})].push_back(id.at({t.v[b][0], t.v[b][1]}));
    for (Vid v = 0; v < pts_.size(); ++v) {
      ++out_.questions.final_stars;
      std::sort(nb[v].begin(), nb[v].end());
      nb[v].erase(std::unique(nb[v].begin(), nb[v].end()), nb[v].end());
      out_.questions.final_asks += final_asks_[v];
      const auto it = held_.find(v);
      if (it != held_.end() && it->second.whole && it->second.star == nb[v]) {
        ++out_.questions.held_final;
        out_.questions.held_final_asks += final_asks_[v];
      }
    }
  }

  Box<2> box_;
  BucketTree tree_;
  std::vector<Point<2>> pts_;
  CellQuestions<BucketTree, Vid, Coords> questions_;
  std::size_t max_vertices_;
  CellRefinement& out_;
  bool check_tree_, log_steps_, held_stars_;
  std::unique_ptr<StarLedger> ledger_;  // with maintained_stars
  Vid first_inserted_ = kNone;          // vertices from here on were inserted by the refinement
  std::map<Vid, HeldStar> held_;
  std::vector<std::size_t> final_asks_;  // by vertex
  std::uint64_t seen_ = 0;
  std::vector<std::uint32_t> step_leaf_ids_;
  std::map<int, std::vector<Entry>> queues_;
  std::vector<Entry> batch_;
  std::vector<std::array<Vid, 2>> pairs_, local_pairs_;
};

}  // namespace

CellRefinement cell_refine(const Box<2>& box, std::span<const Point<2>> points, double min_angle_deg,
                           const CellRefineOptions& options) {
  validate_min_angle(min_angle_deg);
  const auto qs = locate_all(box, points);
  check_separated(qs);
  check_resolution(MeshGrid(box), points, qs);
  validate_mesh_box(box);
  const std::size_t max_vertices = 1000 * (points.size() + 4) + (std::size_t{1} << 20);
  CellRefinement out;
  CellRefiner refiner(box, min_angle_deg, max_vertices, out, options);
  refiner.insert_inputs(points);
  refiner.refine();
  out.triangles = refiner.triangles();
  refiner.check();
  return out;
}

}  // namespace dynmesh::detail
