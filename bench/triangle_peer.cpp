// triangle_peer.cpp — see triangle_peer.hpp. Built into every bench; the call into Triangle
// is compiled only when the build was given its source (DYNMESH_HAVE_TRIANGLE).
#include "triangle_peer.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#if DYNMESH_HAVE_TRIANGLE
// Triangle 1.6's header expects its includer to name the real type and void; C++ ports of
// it (libigl's) ignore these.
#define REAL double
#define VOID void
#ifndef ANSI_DECLARATORS
#define ANSI_DECLARATORS
#endif
#if DYNMESH_TRIANGLE_C_LINKAGE
extern "C" {
#include "triangle.h"
}
#else
#include "triangle.h"
#endif
#endif

namespace bench {

#if DYNMESH_HAVE_TRIANGLE
const bool kHaveTriangle = true;

TriangleMeshSize triangle_quality_mesh(const dynmesh::Box<2>& box, std::span<const dynmesh::Point<2>> points,
                                       double min_angle_deg) {
  const double x0 = box.origin[0], y0 = box.origin[1], x1 = x0 + box.side, y1 = y0 + box.side;
  std::vector<double> xy{x0, y0, x1, y0, x1, y1, x0, y1};  // the corners, then the points
  xy.reserve(2 * (points.size() + 4));
  for (const auto& p : points) xy.insert(xy.end(), {p[0], p[1]});
  std::vector<int> sides{0, 1, 1, 2, 2, 3, 3, 0};

  triangulateio in{}, out{};
  in.pointlist = xy.data();
  in.numberofpoints = static_cast<int>(xy.size() / 2);
  in.segmentlist = sides.data();
  in.numberofsegments = 4;
  char angle[32];
  std::snprintf(angle, sizeof angle, "%.6g", min_angle_deg);
  // p: a planar straight-line graph (the box's sides); z: numbered from 0; Q: quiet;
  // P, B: no output segments or boundary markers; q: the minimum angle.
  std::string switches = std::string("pzQPBq") + angle;
  triangulate(switches.data(), &in, &out, nullptr);

  const TriangleMeshSize size{static_cast<std::size_t>(out.numberofpoints),
                              static_cast<std::size_t>(out.numberoftriangles)};
  // Triangle allocates its outputs with malloc (trimalloc).
  for (void* p : {static_cast<void*>(out.pointlist), static_cast<void*>(out.pointattributelist),
                  static_cast<void*>(out.pointmarkerlist), static_cast<void*>(out.trianglelist),
                  static_cast<void*>(out.triangleattributelist), static_cast<void*>(out.neighborlist),
                  static_cast<void*>(out.segmentlist), static_cast<void*>(out.segmentmarkerlist),
                  static_cast<void*>(out.edgelist), static_cast<void*>(out.edgemarkerlist)})
    std::free(p);
  return size;
}
#else
const bool kHaveTriangle = false;

TriangleMeshSize triangle_quality_mesh(const dynmesh::Box<2>&, std::span<const dynmesh::Point<2>>, double) {
  throw std::logic_error("bench: this build has no Triangle (configure with -DDYNMESH_TRIANGLE_SOURCE=.../triangle.c)");
}
#endif

}  // namespace bench
