"""dynmesh.Mesh and dynmesh.triangulate against the `dynmesh mesh` command, byte for byte."""
import numpy as np
import pytest

import dynmesh
from conftest import format_ele, format_node, read_edits, read_node_points, run_cli, triangle_set


def write_points(path, points):
    path.write_text("".join("%.17g %.17g\n" % (x, y) for x, y in points))


@pytest.mark.parametrize("postprocess", ["hpu", "quadtree"])
def test_mesh_equals_the_command_after_the_same_edits(cli, data, tmp_path, postprocess):
    points = read_node_points(data / "points2d.node")
    m = dynmesh.Mesh(points, postprocess=postprocess)
    for edit in read_edits(data / "edits2d.txt"):
        if edit[0] == "+":
            m.insert(edit[1:])
        else:
            m.erase(edit[1:])
    run_cli(cli, "mesh", data / "points2d.node", "--postprocess", postprocess, "--edits", data / "edits2d.txt",
            "-o", "out", cwd=tmp_path)
    assert format_node(m.vertices, m.box) == (tmp_path / "out.node").read_text()
    assert format_ele(m.triangles) == (tmp_path / "out.ele").read_text()


def test_triangulate_equals_the_command_and_the_dynamic_mesh(cli, data, tmp_path):
    points = read_node_points(data / "points2d.node")
    for angle in (20.7, 30):
        run_cli(cli, "mesh", data / "points2d.node", "--min-angle", angle, "-o", "static", cwd=tmp_path)
        static = dynmesh.triangulate(points, min_angle=angle)
        m = dynmesh.Mesh(points, min_angle=angle)
        assert format_node(static["vertices"], m.box) == (tmp_path / "static.node").read_text()
        assert format_ele(static["triangles"]) == (tmp_path / "static.ele").read_text()
        assert np.array_equal(m.vertices, static["vertices"])
        assert np.array_equal(m.triangles, static["triangles"])
        assert m.vertices.dtype == np.float64 and m.triangles.dtype == np.int64


def test_two_thousand_points_inserted_and_erased_equal_the_command_on_the_final_points(cli, tmp_path):
    rng = np.random.default_rng(7)
    points = rng.random((2000, 2))
    m = dynmesh.Mesh(points)
    assert len(m) == 2000
    new = [tuple(p) for p in 0.1 + 0.8 * rng.random((20, 2))]
    ids = [m.insert(p) for p in new]
    for i in ids[::2]:
        m.erase(i)
    m.erase(tuple(points[5]))
    final = [tuple(p) for k, p in enumerate(points) if k != 5] + new[1::2]
    write_points(tmp_path / "final.txt", final)
    o1, o2, side = m.box
    run_cli(cli, "mesh", "final.txt", "--box", "%.17g" % o1, "%.17g" % o2, "%.17g" % side, "-o", "final",
            cwd=tmp_path)
    assert format_node(m.vertices, m.box) == (tmp_path / "final.node").read_text()
    assert format_ele(m.triangles) == (tmp_path / "final.ele").read_text()
    assert sorted(map(tuple, m.points)) == sorted(final)


@pytest.mark.parametrize("postprocess", ["hpu", "quadtree"])
def test_last_change_replays(data, postprocess):
    points = read_node_points(data / "points2d.node")
    m = dynmesh.Mesh(points, postprocess=postprocess)
    removed, added = m.last_change
    assert removed.shape == (0, 3, 2) and added.shape == (0, 3, 2)
    tris = triangle_set(m.vertices, m.triangles)
    edits = read_edits(data / "edits2d.txt")
    # One propagation per edit, then the rest as one batch.
    for edit in edits[:10]:
        m.insert(edit[1:]) if edit[0] == "+" else m.erase(edit[1:])
        removed, added = m.last_change
        assert {tuple(map(tuple, t)) for t in removed} <= tris
        tris -= {tuple(map(tuple, t)) for t in removed}
        tris |= {tuple(map(tuple, t)) for t in added}
        assert tris == triangle_set(m.vertices, m.triangles)
        assert m.last_update["trace_distance"] > 0
    ids = m.apply(edits[10:])
    assert len(ids) == sum(e[0] == "+" for e in edits[10:])
    removed, added = m.last_change
    tris -= {tuple(map(tuple, t)) for t in removed}
    tris |= {tuple(map(tuple, t)) for t in added}
    assert tris == triangle_set(m.vertices, m.triangles)
    assert set(m.last_update) >= {"trace_distance", "seconds"}
    m.check()


def test_points_ids_and_box():
    m = dynmesh.Mesh([[0.1, 0.2], [0.4, 0.4], [0.41, 0.39]])
    assert list(m.ids) == [0, 1, 2]
    i = m.insert((0.3, 0.7))
    assert i == 3 and list(m.ids) == [0, 1, 2, 3]
    assert tuple(m.points[3]) == (0.3, 0.7)
    assert len(m.box) == 3 and m.min_angle == pytest.approx(20.7)
    assert dynmesh.Mesh([[0.1, 0.2]], box=(0, 0, 1)).box == (0.0, 0.0, 1.0)
    assert dynmesh.Mesh(np.empty((0, 2)), box=(0, 0, 1)).triangles.shape == (2, 3)
    assert dynmesh.__version__.count(".") == 2
