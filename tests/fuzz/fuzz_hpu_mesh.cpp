// fuzz_hpu_mesh — libFuzzer target: HpuMesh, DynHPU's static twin, on fuzzed boxes, angle
// bounds and point sets (fuzz_support.hpp's decoding: coarse dyadic grids, fine grids down
// to the resolution, ulp nudges, special values, arbitrary doubles).
//
// Properties: HpuMesh either refuses the input with InputError (never another exception,
// never a hang: libFuzzer's -timeout) or returns a mesh that passes check_mesh at the angle
// bound with the Delaunay test, every point a vertex; the same points in reverse order give
// the same triangles, bit for bit; check_invariants() holds; the cell refiner
// (src/hpu/cell_refiner.hpp, the same rules answered from the cells) makes the same mesh.
// Complexity: O(m log m) per input for m output vertices (mesh, checker, second mesh).
#include "fuzz_support.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "dynmesh/hpu_mesh.hpp"
#include "dynmesh/mesh.hpp"
#include "dynmesh/mesh_check.hpp"
#include "hpu/cell_refiner.hpp"

using namespace dynmesh_fuzz;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const Box<2> box = PointSource<2>::decode_box(in);
  double angle = kHpuDefaultMinAngle;
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: break;
    case 1: angle = 25.0; break;
    case 2: angle = 30.0; break;
    case 3: angle = in.ConsumeFloatingPointInRange<double>(1.0, 30.0); break;
    case 4: angle = in.ConsumeFloatingPoint<double>(); break;  // mostly refused
    default: angle = 1.0; break;
  }
  PointSource<2> source(in, box);
  std::vector<Point<2>> points;
  const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 48);
  for (std::size_t i = 0; i < n; ++i) points.push_back(source.next(points));

  if (std::getenv("HPU_FUZZ_PRINT")) {
    std::fprintf(stderr, "box %.17g %.17g %.17g angle %.17g n %zu\n", box.origin[0], box.origin[1], box.side, angle,
                 points.size());
    for (const auto& p : points) std::fprintf(stderr, "  %.17g %.17g\n", p[0], p[1]);
  }
  std::vector<Triangle> triangles;
  try {
    const HpuMesh mesh(box, points, angle);
    triangles = mesh.triangles();
    MeshCheckOptions options;
    options.min_angle_deg = angle;
    options.delaunay = true;
    const MeshReport report = check_mesh(mesh.mesh(), box, points, options);
    if (!report.ok()) fail("check_mesh at " + format_exact(angle) + " degrees: " + report.summary());
    try {
      mesh.check_invariants();
    } catch (const std::exception& e) {
      fail(std::string("check_invariants: ") + e.what());
    }
    try {
      const auto cells = dynmesh::detail::cell_refine(box, points, angle);
      check(cells.triangles == triangles, "the cell refiner's mesh differs from the twin's");
    } catch (const std::exception& e) {
      fail(std::string("the cell refiner threw where the twin did not: ") + e.what());
    }
  } catch (const InputError&) {
    return 0;  // refused: the contract only asks for a clear error
  } catch (const std::exception& e) {
    fail(std::string("HpuMesh threw a non-input error: ") + e.what());
  }
  std::reverse(points.begin(), points.end());
  try {
    check(HpuMesh(box, points, angle).triangles() == triangles, "the mesh depends on the order of the points");
  } catch (const std::exception& e) {
    fail(std::string("HpuMesh refused the reversed points: ") + e.what());
  }
  return 0;
}
