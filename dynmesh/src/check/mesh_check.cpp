// The checker of the 2D mesh contract (see dynmesh/mesh_check.hpp for what it checks).
#include "dynmesh/mesh_check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "check/check_support.hpp"
#include "dynmesh/errors.hpp"
#include "dynmesh/predicates.hpp"
#include "geometry/powers_of_two.hpp"
#include "geometry/z_order.hpp"

namespace dynmesh {

std::string_view defect_name(MeshDefect defect) noexcept {
  switch (defect) {
    case MeshDefect::Canonical:
      return "canonical";
    case MeshDefect::BadIndex:
      return "bad-index";
    case MeshDefect::Orientation:
      return "orientation";
    case MeshDefect::OutsideBox:
      return "outside-box";
    case MeshDefect::IsolatedVertex:
      return "isolated-vertex";
    case MeshDefect::MissingCorner:
      return "missing-corner";
    case MeshDefect::EdgeTwice:
      return "edge-twice";
    case MeshDefect::OpenEdge:
      return "open-edge";
    case MeshDefect::VertexInEdge:
      return "vertex-in-edge";
    case MeshDefect::Area:
      return "area";
    case MeshDefect::MissingInput:
      return "missing-input";
    case MeshDefect::SmallAngle:
      return "small-angle";
    case MeshDefect::NotDelaunay:
      return "not-delaunay";
  }
  return "unknown";
}

bool MeshReport::ok() const noexcept {
  for (std::size_t c : counts)
    if (c != 0) return false;
  return true;
}

std::string MeshReport::summary() const {
  if (ok())
    return "mesh ok: angles in [" + format_exact(min_angle_deg) + ", " + format_exact(max_angle_deg) + "] degrees";
  return detail::invalid_summary<MeshDefect>("mesh", *this);
}

namespace {

using Index = std::uint32_t;
using Tri = std::array<Index, 3>;

// The closed domain B, with its side lines at o and fl(o + L) on each axis.
using Domain = detail::ClosedBox<2>;
using Recorder = detail::DefectRecorder<MeshReport, MeshDefect>;

std::string describe_triangle(const Mesh& mesh, std::size_t t) {
  const Tri& tri = mesh.triangles[t];
  std::string s = "triangle " + std::to_string(t) + " [" + std::to_string(tri[0]) + " " + std::to_string(tri[1]) + " " +
                  std::to_string(tri[2]) + "]";
  for (Index i : tri)
    if (i < mesh.num_vertices()) {
      s += ' ';  // appended apart: " " + string trips GCC 12's -Wrestrict false positive (bug 105651)
      s += to_string(mesh.vertices[i]);
    }
  return s;
}

std::string describe_vertex(const Mesh& mesh, Index i) {
  return "vertex " + std::to_string(i) + " " + to_string(mesh.vertices[i]);
}

// ---- VertexInEdge: vertices in Morton order, with a bounding-volume tree over them --------
//
// The vertices are sorted along a Z-order curve of the box (a monotone quantization of each
// axis, so every vertex in an edge's bounding box has its code between the codes of the
// box's lower and upper corners: a contiguous run of the order, found by galloping from the
// edge's ends). A short run is scanned; a long one (the box straddles a big quadrant line) is
// searched in a complete binary tree over blocks of kBlock vertices that stores each node's
// exact bounding box (min and max of the doubles themselves), from the smallest node that
// holds the run, pruning nodes off the edge's bounding box or strictly off its line.
class VertexTree {
 public:
  static constexpr std::size_t kBlock = 8;
  static constexpr std::size_t kScan = 48;  // runs up to this long are scanned directly

  VertexTree(const Mesh& mesh, const Domain& domain)
      : x0_(domain.lo[0]), y0_(domain.lo[1]), position_(mesh.num_vertices(), kAbsent) {
    const double width = domain.hi[0] - domain.lo[0], height = domain.hi[1] - domain.lo[1];
    sx_ = width > 0 ? 0x1p32 / width : 0;
    sy_ = height > 0 ? 0x1p32 / height : 0;
    std::vector<std::pair<std::uint64_t, Index>> order;
    order.reserve(mesh.num_vertices());
    for (Index i = 0; i < mesh.num_vertices(); ++i) {
      const Point<2>& p = mesh.vertices[i];
      if (!std::isfinite(p[0]) || !std::isfinite(p[1])) continue;  // reported as outside the box
      order.emplace_back(code(p), i);
    }
    std::sort(order.begin(), order.end());
    points_.reserve(order.size());
    codes_.reserve(order.size());
    for (const auto& [c, i] : order) {
      position_[i] = points_.size();
      points_.push_back({mesh.vertices[i], i});
      codes_.push_back(c);
    }

    const std::size_t blocks = (points_.size() + kBlock - 1) / kBlock;
    leaves_ = 1;
    while (leaves_ < blocks) leaves_ *= 2;
    nodes_.assign(2 * leaves_, Bounds{});
    for (std::size_t b = 0; b < blocks; ++b) {
      Bounds& box = nodes_[leaves_ + b];
      for (std::size_t k = b * kBlock; k < std::min(points_.size(), (b + 1) * kBlock); ++k) box.add(points_[k].p);
    }
    for (std::size_t n = leaves_ - 1; n >= 1; --n) nodes_[n] = Bounds::merge(nodes_[2 * n], nodes_[2 * n + 1]);
  }

  // Calls found(w) for every vertex w collinear with the edge u-v and strictly between its
  // ends. Both ends must have finite coordinates.
  template <class Found>
  void vertices_inside(const Mesh& mesh, Index u, Index v, Found&& found) const {
    const Point<2>&a = mesh.vertices[u], &b = mesh.vertices[v];
    const Segment seg(a, b);
    const std::size_t pu = position_[u], pv = position_[v];
    const std::size_t lo = first_at_least(std::min(pu, pv), code({seg.lox, seg.loy}));
    const std::size_t hi = first_above(std::max(pu, pv), code({seg.hix, seg.hiy}));
    if (hi - lo <= kScan) {
      scan(seg, lo, hi, found);
      return;
    }
    std::size_t first = leaves_ + lo / kBlock, last = leaves_ + (hi - 1) / kBlock;
    while (first != last) first /= 2, last /= 2;  // the smallest node holding the run
    std::size_t stack[128];
    std::size_t top = 0;
    stack[top++] = first;
    while (top > 0) {
      const std::size_t n = stack[--top];
      const Bounds& box = nodes_[n];
      if (box.hix < seg.lox || box.lox > seg.hix || box.hiy < seg.loy || box.loy > seg.hiy) continue;
      if (!seg.axis_parallel && box.off_line(a, seg.dx, seg.dy)) continue;
      if (n < leaves_) {
        stack[top++] = 2 * n + 1;
        stack[top++] = 2 * n;
        continue;
      }
      const std::size_t block = n - leaves_;
      scan(seg, std::max(lo, block * kBlock), std::min(hi, (block + 1) * kBlock), found);
    }
  }

 private:
  static constexpr std::size_t kAbsent = std::numeric_limits<std::size_t>::max();

  struct Located {
    Point<2> p;
    Index index;
  };

  struct Segment {
    const Point<2>&a, &b;
    double lox, hix, loy, hiy, dx, dy;
    bool axis_parallel;
    Segment(const Point<2>& from, const Point<2>& to)
        : a(from),
          b(to),
          lox(std::min(from[0], to[0])),
          hix(std::max(from[0], to[0])),
          loy(std::min(from[1], to[1])),
          hiy(std::max(from[1], to[1])),
          dx(to[0] - from[0]),
          dy(to[1] - from[1]),
          axis_parallel(dx == 0 || dy == 0) {}
  };

  template <class Found>
  void scan(const Segment& seg, std::size_t from, std::size_t to, Found& found) const {
    for (std::size_t k = from; k < to; ++k) {
      const Point<2>& w = points_[k].p;
      if (w[0] < seg.lox || w[0] > seg.hix || w[1] < seg.loy || w[1] > seg.hiy) continue;
      if (w == seg.a || w == seg.b) continue;
      // In the closed bounding box and not an end: collinear means strictly between. For an
      // axis-parallel edge the box is the segment itself.
      if (seg.axis_parallel || orient2d(seg.a, seg.b, w) == 0) found(points_[k].index);
    }
  }

  // The first position in [0, start] whose code is >= c (codes_[start] >= c), galloping
  // down from start: cheap when the answer is near.
  std::size_t first_at_least(std::size_t start, std::uint64_t c) const noexcept {
    std::size_t high = start, step = 1;
    while (step <= high && codes_[high - step] >= c) {
      high -= step;
      step *= 2;
    }
    const std::size_t low = step <= high ? high - step : 0;
    return static_cast<std::size_t>(std::lower_bound(codes_.begin() + static_cast<std::ptrdiff_t>(low),
                                                     codes_.begin() + static_cast<std::ptrdiff_t>(high), c) -
                                    codes_.begin());
  }

  // The first position after start whose code is > c (codes_[start] <= c), galloping up.
  std::size_t first_above(std::size_t start, std::uint64_t c) const noexcept {
    std::size_t low = start, step = 1;
    while (low + step < codes_.size() && codes_[low + step] <= c) {
      low += step;
      step *= 2;
    }
    const std::size_t high = std::min(codes_.size(), low + step);
    return static_cast<std::size_t>(std::upper_bound(codes_.begin() + static_cast<std::ptrdiff_t>(low) + 1,
                                                     codes_.begin() + static_cast<std::ptrdiff_t>(high), c) -
                                    codes_.begin());
  }

  std::uint64_t code(const Point<2>& p) const noexcept {
    return detail::z_order(quantize((p[0] - x0_) * sx_), quantize((p[1] - y0_) * sy_));
  }

  struct Bounds {
    double lox = std::numeric_limits<double>::infinity(), hix = -std::numeric_limits<double>::infinity();
    double loy = std::numeric_limits<double>::infinity(), hiy = -std::numeric_limits<double>::infinity();

    void add(const Point<2>& p) noexcept {
      lox = std::min(lox, p[0]);
      hix = std::max(hix, p[0]);
      loy = std::min(loy, p[1]);
      hiy = std::max(hiy, p[1]);
    }
    static Bounds merge(const Bounds& l, const Bounds& r) noexcept {
      return Bounds{std::min(l.lox, r.lox), std::max(l.hix, r.hix), std::min(l.loy, r.loy), std::max(l.hiy, r.hiy)};
    }

    // True when the whole box lies strictly on one side of the line through a with direction
    // (dx, dy), certified in double: f(c) = dx·(cy − ay) − dy·(cx − ax) is linear, so its
    // extremes over the box are at the corners chosen by the signs of dx and dy. Each is
    // trusted only beyond an error bound (Shewchuk's for orient2d is 3.3e-16 times the
    // permanent; 1e-15 leaves margin, 1e-300 covers underflow), so pruning never loses a
    // vertex; a box it cannot certify is simply visited.
    bool off_line(const Point<2>& a, double dx, double dy) const noexcept {
      const double hi_cx = dy > 0 ? lox : hix, hi_cy = dx > 0 ? hiy : loy;  // maximizes f
      const double lo_cx = dy > 0 ? hix : lox, lo_cy = dx > 0 ? loy : hiy;  // minimizes f
      const double ahx = hi_cx - a[0], ahy = hi_cy - a[1], alx = lo_cx - a[0], aly = lo_cy - a[1];
      const double fmax = dx * ahy - dy * ahx, fmin = dx * aly - dy * alx;
      const double emax = 1e-15 * (std::abs(dx * ahy) + std::abs(dy * ahx)) + 1e-300;
      const double emin = 1e-15 * (std::abs(dx * aly) + std::abs(dy * alx)) + 1e-300;
      return fmax < -emax || fmin > emin;
    }
  };

  static std::uint32_t quantize(double t) noexcept {
    if (!(t > 0)) return 0;
    if (t >= 0x1p32) return 0xffffffffu;
    return static_cast<std::uint32_t>(t);
  }

  double x0_, y0_, sx_ = 0, sy_ = 0;   // the quantization: code() is monotone in x and in y
  std::vector<std::size_t> position_;  // vertex index -> place in points_ (kAbsent: not finite)
  std::vector<Located> points_;        // in Morton order
  std::vector<std::uint64_t> codes_;   // codes_[k]: the Morton code of points_[k]
  std::vector<Bounds> nodes_;          // heap layout: node n has children 2n, 2n+1; leaves from leaves_
  std::size_t leaves_ = 1;
};

// ---- the directed edges, grouped by their start vertex ---------------------------------

struct OutEdge {
  Index to;
  Index tri;
  friend bool operator<(const OutEdge& l, const OutEdge& r) noexcept {
    return l.to < r.to || (l.to == r.to && l.tri < r.tri);
  }
};

// Compressed rows: out[start[u] .. start[u+1]) are the edges leaving u, sorted by end.
struct EdgeTable {
  std::vector<std::size_t> start;
  std::vector<OutEdge> out;

  std::span<const OutEdge> from(Index u) const noexcept { return {out.data() + start[u], start[u + 1] - start[u]}; }
  // The number of directed edges v -> u, and the triangle of the first.
  std::pair<std::size_t, Index> count(Index v, Index u) const noexcept {
    const auto row = from(v);
    const auto lo = std::lower_bound(row.begin(), row.end(), OutEdge{u, 0});
    auto hi = lo;
    while (hi != row.end() && hi->to == u) ++hi;
    return {static_cast<std::size_t>(hi - lo), lo == hi ? Index{0} : lo->tri};
  }
};

EdgeTable build_edges(const Mesh& mesh, const std::vector<char>& well_formed) {
  EdgeTable table;
  const std::size_t n = mesh.num_vertices();
  table.start.assign(n + 1, 0);
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t)
    if (well_formed[t])
      for (Index i : mesh.triangles[t]) ++table.start[i + 1];
  for (std::size_t i = 0; i < n; ++i) table.start[i + 1] += table.start[i];
  table.out.resize(table.start[n]);
  std::vector<std::size_t> fill(table.start.begin(), table.start.end() - 1);
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    if (!well_formed[t]) continue;
    const Tri& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) table.out[fill[tri[k]]++] = OutEdge{tri[(k + 1) % 3], static_cast<Index>(t)};
  }
  for (std::size_t u = 0; u < n; ++u)
    std::sort(table.out.begin() + static_cast<std::ptrdiff_t>(table.start[u]),
              table.out.begin() + static_cast<std::ptrdiff_t>(table.start[u + 1]));
  return table;
}

// The corner of triangle `tri` that is neither u nor v.
Index opposite(const Tri& tri, Index u, Index v) noexcept {
  for (Index i : tri)
    if (i != u && i != v) return i;
  return tri[0];
}

}  // namespace

double corner_angle_deg(const Point<2>& at, const Point<2>& p, const Point<2>& q) noexcept {
  double ux = p[0] - at[0], uy = p[1] - at[1], vx = q[0] - at[0], vy = q[1] - at[1];
  // Scaled by a power of two (exact, and the angle does not change) so that the products
  // neither overflow in a box of side near 1e308 nor underflow to 0 in one near 1e-300.
  detail::to_unit_frame(ux, uy, vx, vy);
  const double cross = ux * vy - uy * vx, dot = ux * vx + uy * vy;
  return std::atan2(std::abs(cross), dot) * (180.0 / std::numbers::pi);
}

namespace {

/// Lengths in units of 2^k with 2^k <= L < 2^(k+1) (exact scaling), so that neither the
/// box's area nor a triangle's overflows or underflows in a box of extreme size.
struct SideScale {
  int exponent = 0;
  explicit SideScale(const Box<2>& box) : exponent(std::isfinite(box.side) && box.side > 0 ? std::ilogb(box.side) : 0) {}
  double operator()(double length) const { return std::ldexp(length, -exponent); }
};

/// What the triangle pass learns for the later passes.
struct TriangleScan {
  std::vector<char> well_formed;  // indices in range and distinct
  std::vector<char> ccw;          // strictly counter-clockwise
  detail::CompensatedSum twice_area;  // in units of SideScale squared
};

/// Per triangle: indices, canonical rotation and order, orientation, area, angles.
TriangleScan check_triangles(const Mesh& mesh, const SideScale& scaled, const MeshCheckOptions& options,
                             MeshReport& report, Recorder& record) {
  const std::size_t nv = mesh.num_vertices(), nt = mesh.num_triangles();
  const auto& vertices = mesh.vertices;
  TriangleScan scan{std::vector<char>(nt, 0), std::vector<char>(nt, 0), {}};
  double min_angle = std::numeric_limits<double>::infinity(), max_angle = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    const Tri& tri = mesh.triangles[t];
    if (t > 0 && tri < mesh.triangles[t - 1])
      record.add(MeshDefect::Canonical, [&] { return describe_triangle(mesh, t) + " is out of order"; });
    if (tri[0] >= nv || tri[1] >= nv || tri[2] >= nv || tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      record.add(MeshDefect::BadIndex,
                 [&] { return describe_triangle(mesh, t) + " names a missing vertex or one twice"; });
      continue;
    }
    scan.well_formed[t] = 1;
    if (!(tri[0] < tri[1] && tri[0] < tri[2]))
      record.add(MeshDefect::Canonical,
                 [&] { return describe_triangle(mesh, t) + " does not start at its smallest index"; });
    const Point<2>&a = vertices[tri[0]], &b = vertices[tri[1]], &c = vertices[tri[2]];
    const int turn = orient2d(a, b, c);
    if (turn > 0) {
      scan.ccw[t] = 1;
    } else {
      record.add(MeshDefect::Orientation, [&] {
        return describe_triangle(mesh, t) + (turn < 0 ? " is clockwise" : " is degenerate (collinear corners)");
      });
    }
    const double twice =
        scaled(b[0] - a[0]) * scaled(c[1] - a[1]) - scaled(b[1] - a[1]) * scaled(c[0] - a[0]);
    scan.twice_area.add(twice);

    const double angles[3] = {corner_angle_deg(a, b, c), corner_angle_deg(b, c, a), corner_angle_deg(c, a, b)};
    const double lo = std::min({angles[0], angles[1], angles[2]}), hi = std::max({angles[0], angles[1], angles[2]});
    min_angle = std::min(min_angle, lo);
    max_angle = std::max(max_angle, hi);
    if (lo < options.min_angle_deg)
      record.add(MeshDefect::SmallAngle, [&] {
        return describe_triangle(mesh, t) + " has an angle of " + format_exact(lo) + " degrees, below " +
               format_exact(options.min_angle_deg);
      });
  }
  if (std::isfinite(min_angle)) {
    report.min_angle_deg = min_angle;
    report.max_angle_deg = max_angle;
  }
  return scan;
}

/// The triangles' area is the box's.
void check_area(const Domain& domain, const SideScale& scaled, const TriangleScan& scan, Recorder& record) {
  const double box_area = scaled(domain.hi[0] - domain.lo[0]) * scaled(domain.hi[1] - domain.lo[1]);
  const double mesh_area = scan.twice_area.value() / 2;
  if (!(std::abs(mesh_area - box_area) <= 1e-9 * box_area))
    record.add(MeshDefect::Area, [&] {
      const std::string unit = scaled.exponent == 0 ? "" : " (in units of 2^" + std::to_string(2 * scaled.exponent) + ")";
      return "the triangles' area " + format_exact(mesh_area) + " differs from the box's " + format_exact(box_area) +
             unit;
    });
}

/// Edges: matched in opposite directions inside, on a side of the box when used once; every
/// vertex on one; Delaunay across each interior edge if asked. Returns each edge once.
std::vector<std::pair<Index, Index>> check_edges(const Mesh& mesh, const Domain& domain, const TriangleScan& scan,
                                                 const MeshCheckOptions& options, Recorder& record) {
  const std::size_t nv = mesh.num_vertices();
  const auto& vertices = mesh.vertices;
  const EdgeTable edges = build_edges(mesh, scan.well_formed);
  std::vector<std::pair<Index, Index>> undirected;
  undirected.reserve(edges.out.size() / 2 + nv);
  for (Index u = 0; u < nv; ++u) {
    const auto row = edges.from(u);
    if (row.empty()) {
      record.add(MeshDefect::IsolatedVertex, [&] { return describe_vertex(mesh, u) + " belongs to no triangle"; });
      continue;
    }
    for (std::size_t k = 0; k < row.size(); ++k) {
      const Index v = row[k].to, t = row[k].tri;
      if (k > 0 && row[k - 1].to == v) {
        record.add(MeshDefect::EdgeTwice, [&] {
          return "edge " + std::to_string(u) + " -> " + std::to_string(v) + " " + to_string(vertices[u]) + " -> " +
                 to_string(vertices[v]) + " is used by triangles " + std::to_string(row[k - 1].tri) + " and " +
                 std::to_string(t);
        });
        continue;
      }
      // Plain variables, not a structured binding: the lambdas below capture them.
      const std::pair<std::size_t, Index> back = edges.count(v, u);
      const std::size_t reverse = back.first;
      const Index across = back.second;
      if (reverse == 0) {
        if (!domain.on_one_side(std::array{vertices[u], vertices[v]}))
          record.add(MeshDefect::OpenEdge, [&] {
            return "edge " + std::to_string(u) + " -> " + std::to_string(v) + " " + to_string(vertices[u]) + " -> " +
                   to_string(vertices[v]) + " of triangle " + std::to_string(t) +
                   " has no neighbour and is not on the box boundary";
          });
        undirected.emplace_back(u, v);
        continue;
      }
      if (u > v) continue;  // interior edges are handled once, from their smaller end
      undirected.emplace_back(u, v);
      if (options.delaunay && scan.ccw[t] && scan.ccw[across]) {
        const Index apex = opposite(mesh.triangles[t], u, v), far = opposite(mesh.triangles[across], u, v);
        if (incircle(vertices[u], vertices[v], vertices[apex], vertices[far]) > 0)
          record.add(MeshDefect::NotDelaunay, [&] {
            return describe_vertex(mesh, far) + " of triangle " + std::to_string(across) +
                   " is strictly inside the circumcircle of triangle " + std::to_string(t) + " across edge " +
                   std::to_string(u) + " - " + std::to_string(v);
          });
      }
    }
  }
  return undirected;
}

/// No vertex strictly inside an edge (edges with a non-finite end are reported elsewhere).
void check_vertices_off_edges(const Mesh& mesh, const Domain& domain,
                              const std::vector<std::pair<Index, Index>>& undirected, Recorder& record) {
  const auto& vertices = mesh.vertices;
  const VertexTree tree(mesh, domain);
  for (const auto& edge : undirected) {
    const Index u = edge.first, v = edge.second;
    const Point<2>&a = vertices[u], &b = vertices[v];
    if (!std::isfinite(a[0]) || !std::isfinite(a[1]) || !std::isfinite(b[0]) || !std::isfinite(b[1])) continue;
    tree.vertices_inside(mesh, u, v, [&](Index w) {
      record.add(MeshDefect::VertexInEdge, [&] {
        return describe_vertex(mesh, w) + " lies inside edge " + std::to_string(u) + " - " + std::to_string(v) + " " +
               to_string(a) + " - " + to_string(b);
      });
    });
  }
}

}  // namespace

MeshReport check_mesh(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                      const MeshCheckOptions& options, std::size_t max_problems) {
  MeshReport report;
  Recorder record(report, max_problems);
  const Domain domain(box);
  const SideScale scaled(box);

  // Canonical vertex order. Lookups below need a sorted list; a broken mesh gets a copy.
  const bool vertices_sorted = detail::check_vertex_order<MeshDefect>(mesh.vertices, &xy_less, "(x, y)", record);
  const detail::PointLookup<2, decltype(&xy_less)> lookup(mesh.vertices, vertices_sorted, &xy_less);
  detail::check_box<MeshDefect>(mesh.vertices, domain, lookup, record,
                                [&](std::size_t i) { return describe_vertex(mesh, static_cast<Index>(i)); });

  const TriangleScan scan = check_triangles(mesh, scaled, options, report, record);
  check_area(domain, scaled, scan, record);
  const std::vector<std::pair<Index, Index>> undirected = check_edges(mesh, domain, scan, options, record);
  check_vertices_off_edges(mesh, domain, undirected, record);
  detail::check_inputs<MeshDefect>(inputs, lookup, record);
  return report;
}

void require_valid_mesh(const Mesh& mesh, const Box<2>& box, std::span<const Point<2>> inputs,
                        const MeshCheckOptions& options, std::size_t max_problems) {
  const MeshReport report = check_mesh(mesh, box, inputs, options, max_problems);
  if (!report.ok()) throw InvariantError(report.summary());
}

}  // namespace dynmesh
