"""dynmesh.Mesh on (n, 3) points: the octree's tetrahedral mesh (docs/FORMATS.md, "`dynmesh mesh`
in 3D"), against the `dynmesh mesh` command byte for byte, its change feed replayed, its errors,
and meshio's "tetra" cells."""
import math

import numpy as np
import pytest

import dynmesh
from conftest import format_ele, format_node, read_edits, read_node_points, run_cli, triangle_set


def write_points(path, points):
    path.write_text("".join(" ".join("%.17g" % c for c in p) + "\n" for p in points))


def snapshot(m):
    removed, added = m.last_change
    return (m.vertices.tobytes(), m.tetrahedra.tobytes(), m.points.tobytes(), m.ids.tobytes(), removed.tobytes(),
            added.tobytes())


def expect(kind, call, text=None, index=None):
    with pytest.raises(ValueError) as info:
        call()
    err = info.value
    assert isinstance(err, dynmesh.InputError)
    assert err.kind == kind, str(err)
    if index is not None:
        assert err.index == index, str(err)
    if text:
        assert text in str(err), str(err)
    return err


@pytest.fixture(scope="module")
def cloud():
    return np.random.default_rng(11).random((300, 3))


@pytest.mark.parametrize("dim_option", [[], ["--dim", "3"]])
def test_mesh_equals_the_command_after_the_same_edits(cli, data, tmp_path, dim_option):
    points = read_node_points(data / "points3d.node")
    assert points.shape[1] == 3
    m = dynmesh.Mesh(points)
    assert m.dim == 3 and len(m.box) == 4
    for edit in read_edits(data / "edits3d.txt"):
        if edit[0] == "+":
            m.insert(edit[1:])
        else:
            m.erase(edit[1:])
    run_cli(cli, "mesh", data / "points3d.node", *dim_option, "--edits", data / "edits3d.txt", "-o", "out",
            cwd=tmp_path)
    assert format_node(m.vertices, m.box) == (tmp_path / "out.node").read_text()
    assert format_ele(m.tetrahedra) == (tmp_path / "out.ele").read_text()
    assert m.vertices.dtype == np.float64 and m.vertices.shape[1] == 3
    assert m.tetrahedra.dtype == np.int64 and m.tetrahedra.shape[1] == 4


def test_random_points_inserted_and_erased_equal_the_command_on_the_final_points(cli, tmp_path, cloud):
    rng = np.random.default_rng(5)
    m = dynmesh.Mesh(cloud)
    assert len(m) == len(cloud)
    new = [tuple(p) for p in 0.1 + 0.8 * rng.random((12, 3))]
    ids = [m.insert(p) for p in new]
    for i in ids[::2]:
        m.erase(i)
    m.erase(tuple(cloud[7]))
    final = [tuple(p) for k, p in enumerate(cloud) if k != 7] + new[1::2]
    # Plain text of x y z lines, without --dim: meshed in 3D (the file's first line sets it).
    write_points(tmp_path / "final.xyz", final)
    box = ["%.17g" % v for v in m.box]
    run_cli(cli, "mesh", "final.xyz", "--box", *box, "-o", "final", "--check", cwd=tmp_path)
    assert format_node(m.vertices, m.box) == (tmp_path / "final.node").read_text()
    assert format_ele(m.tetrahedra) == (tmp_path / "final.ele").read_text()
    assert sorted(map(tuple, m.points)) == sorted(final)
    m.check()


def test_insert_erase_round_trips(cloud):
    m = dynmesh.Mesh(cloud)
    vertices, tets = m.vertices, m.tetrahedra
    i = m.insert((0.5, 0.25, 0.75))
    assert i == len(cloud) and m.ids[-1] == i
    assert tuple(m.points[-1]) == (0.5, 0.25, 0.75)
    m.erase(i)
    assert np.array_equal(m.vertices, vertices) and np.array_equal(m.tetrahedra, tets)
    # By coordinates, and as one batch.
    m.insert((0.5, 0.25, 0.75))
    m.erase((0.5, 0.25, 0.75))
    assert np.array_equal(m.tetrahedra, tets)
    ids = m.apply([("-", *cloud[3]), ("+", 0.3, 0.6, 0.2)])
    assert len(ids) == 1
    m.apply([("-", 0.3, 0.6, 0.2), ("+", *cloud[3])])
    assert np.array_equal(m.vertices, vertices) and np.array_equal(m.tetrahedra, tets)
    assert len(m) == len(cloud)


def test_last_change_replays(data):
    points = read_node_points(data / "points3d.node")
    m = dynmesh.Mesh(points)
    removed, added = m.last_change
    assert removed.shape == (0, 4, 3) and added.shape == (0, 4, 3)
    tets = triangle_set(m.vertices, m.tetrahedra)
    edits = read_edits(data / "edits3d.txt")
    # One propagation per edit, then the rest as one batch.
    for edit in edits[:6]:
        m.insert(edit[1:]) if edit[0] == "+" else m.erase(edit[1:])
        removed, added = m.last_change
        assert removed.shape[1:] == (4, 3) and added.shape[1:] == (4, 3)
        gone = {tuple(map(tuple, t)) for t in removed}
        assert gone <= tets
        tets = (tets - gone) | {tuple(map(tuple, t)) for t in added}
        assert tets == triangle_set(m.vertices, m.tetrahedra)
        assert m.last_update["trace_distance"] > 0
    m.apply(edits[6:])
    removed, added = m.last_change
    tets = (tets - {tuple(map(tuple, t)) for t in removed}) | {tuple(map(tuple, t)) for t in added}
    assert tets == triangle_set(m.vertices, m.tetrahedra)
    assert set(m.last_update) >= {"trace_distance", "seconds"}


def test_tetrahedra_are_canonical_and_positive(cloud):
    m = dynmesh.Mesh(cloud)
    v, t = m.vertices, m.tetrahedra
    rows = [tuple(r) for r in t]
    assert rows == sorted(rows) and len(set(rows)) == len(rows)
    assert np.all(t[:, 0] < t[:, 1:].min(axis=1)) and np.all(t[:, 1] < t[:, 2:].min(axis=1))
    a, b, c, d = (v[t[:, k]] for k in range(4))
    assert np.all(np.linalg.det(np.stack([b - a, c - a, d - a], axis=1)) > 0)
    # The tetrahedra fill the box.
    side = m.box[3]
    volume = np.abs(np.linalg.det(np.stack([b - a, c - a, d - a], axis=1))).sum() / 6
    assert volume == pytest.approx(side ** 3, rel=1e-9)


def test_cells_name_the_simplices_in_either_dimension(cloud):
    m3 = dynmesh.Mesh(cloud)
    assert m3.cell_type == "tetra" and np.array_equal(m3.cells, m3.tetrahedra)
    assert m3.min_angle is None
    with pytest.raises(AttributeError, match="tetrahedra"):
        m3.triangles
    d = m3.mesh()
    assert set(d) == {"vertices", "tetrahedra"} and np.array_equal(d["tetrahedra"], m3.tetrahedra)
    m2 = dynmesh.Mesh(cloud[:, :2])
    assert m2.dim == 2 and m2.cell_type == "triangle" and np.array_equal(m2.cells, m2.triangles)
    with pytest.raises(AttributeError, match="triangles"):
        m2.tetrahedra
    # An empty (0, 3) array with a box: the box's mesh alone, its eight corners.
    empty = dynmesh.Mesh(np.empty((0, 3)), box=(0, 0, 0, 1))
    assert empty.vertices.shape == (8, 3) and empty.box == (0.0, 0.0, 0.0, 1.0)


def test_postprocess_defaults_to_the_octree_mesh_and_refuses_the_2d_options(cloud):
    assert np.array_equal(dynmesh.Mesh(cloud).tetrahedra, dynmesh.Mesh(cloud, postprocess="quadtree").tetrahedra)
    expect("Malformed", lambda: dynmesh.Mesh(cloud, postprocess="hpu"), text="\"hpu\" is 2D only")
    expect("Malformed", lambda: dynmesh.Mesh(cloud, min_angle=20), text="min_angle is 2D only")
    expect("Malformed", lambda: dynmesh.Mesh(cloud, min_angle=10, postprocess="quadtree"), text="2D only")
    expect("Malformed", lambda: dynmesh.Mesh(cloud, postprocess="delaunay"), text="quadtree")
    expect("Malformed", lambda: dynmesh.Mesh(np.zeros((3, 4))), text="(n, 2) or (n, 3)")
    expect("Malformed", lambda: dynmesh.Mesh(cloud, box=(0, 0, 1)), text="o3")


def test_failed_updates_change_nothing(cloud):
    m = dynmesh.Mesh(cloud)
    m.insert((0.6, 0.6, 0.6))  # a last_change to keep
    before = snapshot(m)
    nan = float("nan")
    expect("NotFinite", lambda: m.insert((nan, 0.5, 0.5)))
    expect("NotFinite", lambda: m.insert((0.5, 0.5, math.inf)))
    expect("OutsideBox", lambda: m.insert((100.0, 0.5, 0.5)))
    expect("Duplicate", lambda: m.insert(tuple(cloud[4])))
    expect("Absent", lambda: m.erase((0.5, 0.5, 0.5)), text="not in the set")
    expect("Absent", lambda: m.erase(10**6))
    expect("Malformed", lambda: m.insert((0.5, 0.5)), text="3 numbers")
    expect("Malformed", lambda: m.erase((0.5, 0.5)), text="3 numbers")
    expect("Duplicate", lambda: m.apply([("+", 0.2, 0.6, 0.1), ("+", *cloud[4])]), index=1)
    expect("Absent", lambda: m.apply([("+", 0.2, 0.6, 0.1), ("-", 0.2, 0.6, 0.1), ("-", 0.2, 0.6, 0.1)]), index=2)
    expect("Malformed", lambda: m.apply([("+", 0.2, 0.6, 0.1), ("+", 0.2, 0.6)]), index=1)
    assert snapshot(m) == before
    m.check()


def test_bad_construction():
    expect("NotFinite", lambda: dynmesh.Mesh([[0.1, 0.2, 0.3], [float("nan"), 0.3, 0.4]]))
    err = expect("Duplicate", lambda: dynmesh.Mesh([[0.1, 0.2, 0.3], [0.5, 0.5, 0.5], [0.1, 0.2, 0.3]]), index=2)
    assert err.indices == (0, 2)
    expect("OutsideBox", lambda: dynmesh.Mesh([[0.1, 0.2, 0.3], [0.9, 0.9, 0.9]], box=(0, 0, 0, 0.5)))
    expect("Empty", lambda: dynmesh.Mesh(np.empty((0, 3))))


def test_to_meshio_gives_tetra_cells(tmp_path, cloud):
    meshio = pytest.importorskip("meshio")
    m = dynmesh.Mesh(cloud[:100])
    m.insert((0.5, 0.5, 0.5))
    out = m.to_meshio()
    assert isinstance(out, meshio.Mesh)
    assert np.array_equal(out.points, m.vertices)
    tetra = [c.data for c in out.cells if c.type == "tetra"]
    assert len(tetra) == 1 and np.array_equal(tetra[0], m.tetrahedra)
    path = tmp_path / "mesh.vtk"
    meshio.write(path, out)
    back = meshio.read(path)
    assert np.array_equal(back.points, m.vertices)
    assert np.array_equal([c.data for c in back.cells if c.type == "tetra"][0], m.tetrahedra)
