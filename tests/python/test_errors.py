"""Bad input raises dynmesh.InputError (a ValueError) with the library's message and the
failing index, and changes nothing: the bad inputs of the C++ tests (dynamic_mesh_test.cpp,
dynamic_quadtree_test.cpp, tests/cli/) through the Python API."""
import math

import numpy as np
import pytest

import dynmesh

POINTS = [[0.1, 0.2], [0.4, 0.4], [0.41, 0.39], [0.8, 0.3]]


def snapshot(m):
    removed, added = m.last_change
    return (m.vertices.tobytes(), m.triangles.tobytes(), m.points.tobytes(), m.ids.tobytes(), removed.tobytes(),
            added.tobytes())


ANY = object()


def expect(kind, call, index=ANY, text=None):
    with pytest.raises(ValueError) as info:
        call()
    err = info.value
    assert isinstance(err, dynmesh.InputError)
    assert err.kind == kind, str(err)
    if index is not ANY:
        assert err.index == index, str(err)
        assert err.index is None or err.index == err.indices[-1]
    if text:
        assert text in str(err)
    return err


@pytest.mark.parametrize("postprocess", ["hpu", "quadtree"])
def test_failed_updates_change_nothing(postprocess):
    m = dynmesh.Mesh(POINTS, postprocess=postprocess)
    m.insert((0.6, 0.6))  # a last_change to keep
    before = snapshot(m)
    nan = float("nan")
    expect("NotFinite", lambda: m.insert((nan, 0.5)))
    expect("NotFinite", lambda: m.insert((0.5, math.inf)))
    expect("OutsideBox", lambda: m.insert((100.0, 0.5)))
    expect("Duplicate", lambda: m.insert((0.4, 0.4)))
    expect("Absent", lambda: m.erase((0.5, 0.5)), text="not in the set")
    expect("Absent", lambda: m.erase(99))
    expect("Absent", lambda: m.erase(-1), index=None)
    expect("Malformed", lambda: m.insert((0.5,)))
    expect("Malformed", lambda: m.insert("ab"))
    # A batch is validated as a whole: the failing edit's index, and no edit applied.
    expect("Duplicate", lambda: m.apply([("+", 0.2, 0.6), ("+", 0.4, 0.4)]), index=1)
    expect("Absent", lambda: m.apply([("+", 0.2, 0.6), ("-", 0.2, 0.6), ("-", 0.2, 0.6)]), index=2)
    expect("NotFinite", lambda: m.apply([("+", 0.2, 0.6), ("+", nan, 0.1)]), index=1)
    expect("Malformed", lambda: m.apply([("+", 0.2, 0.6), ("*", 0.3, 0.3)]), index=1, text="sign")
    expect("Malformed", lambda: m.apply([("+", 0.2)]), index=0)
    expect("Malformed", lambda: m.apply([("+", 0.2, "x")]), index=0)
    assert snapshot(m) == before
    m.check()


def test_bad_construction():
    expect("NotFinite", lambda: dynmesh.Mesh([[0.1, 0.2], [float("nan"), 0.3]]))
    err = expect("Duplicate", lambda: dynmesh.Mesh([[0.1, 0.2], [0.5, 0.5], [0.1, 0.2]]), index=2)
    assert err.indices == (0, 2)
    # Different points with one located position, and points the mesh cannot resolve.
    err = expect("Duplicate", lambda: dynmesh.Mesh([[0.0, 0.0], [1.0, 1.0], [1e-20, 0.0]]), index=2)
    assert err.indices == (0, 2)
    expect("Resolution", lambda: dynmesh.Mesh([[0.0, 0.0], [1.0, 1.0], [1e-12, 0.0]]), index=2,
           text="spread beyond the resolution")
    expect("OutsideBox", lambda: dynmesh.Mesh(POINTS, box=(0, 0, 0.5)), index=3)
    expect("OutsideBox", lambda: dynmesh.Mesh(POINTS, box=(0, 0, -1)))
    expect("Malformed", lambda: dynmesh.Mesh(POINTS, box=(0, 0)))
    expect("Malformed", lambda: dynmesh.Mesh(POINTS, min_angle=45))
    expect("Malformed", lambda: dynmesh.Mesh(POINTS, min_angle="steep"), text="min_angle must be a number")
    expect("Malformed", lambda: dynmesh.triangulate(POINTS, min_angle=[1]))
    expect("Malformed", lambda: dynmesh.Mesh(POINTS, min_angle=25, postprocess="quadtree"))
    expect("Malformed", lambda: dynmesh.Mesh(POINTS, postprocess="delaunay"))
    expect("Malformed", lambda: dynmesh.Mesh(np.zeros((3, 4))))  # (n, 3) is the 3D mesh (test_mesh3d.py)
    expect("Empty", lambda: dynmesh.Mesh(np.empty((0, 2))))
    expect("Malformed", lambda: dynmesh.triangulate(POINTS, min_angle=0.5))
    expect("Duplicate", lambda: dynmesh.triangulate([[0.1, 0.2], [0.1, 0.2]]))


def test_quadtree_errors_change_nothing():
    t = dynmesh.Quadtree([[0.1, 0.2, 0.3], [0.5, 0.5, 0.5]], dim=3)
    before = [a.tobytes() for a in t.leaves()]
    expect("Duplicate", lambda: t.insert((0.5, 0.5, 0.5)))
    expect("Malformed", lambda: t.insert((0.5, 0.5)))
    expect("Absent", lambda: t.apply([("+", 0.2, 0.2, 0.2), ("-", 0.3, 0.3, 0.3)]), index=1)
    expect("Malformed", lambda: dynmesh.Quadtree([[0.1, 0.2]], dim=4))
    assert [a.tobytes() for a in t.leaves()] == before
    assert len(t) == 2
