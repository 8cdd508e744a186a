"""Two threads, each updating its own Mesh with the GIL released, get exactly what they get
one after the other."""
import threading

import numpy as np

import dynmesh


def workload(seed):
    rng = np.random.default_rng(seed)
    points = rng.random((3000, 2))
    m = dynmesh.Mesh(points)
    changes = []
    for k in range(40):
        if k % 2:
            m.erase(tuple(points[k]))
        else:
            m.insert(tuple(0.05 + 0.9 * rng.random(2)))
        removed, added = m.last_change
        changes.append((removed.tobytes(), added.tobytes()))
    return m.vertices.tobytes(), m.triangles.tobytes(), changes


def test_two_threads_equal_one_after_the_other():
    alone = [workload(1), workload(2)]
    together = [None, None]

    def run(k):
        together[k] = workload(k + 1)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert together == alone


def test_the_gil_is_released_during_a_build():
    # While one thread builds a large mesh, another keeps running Python code.
    rng = np.random.default_rng(5)
    points = rng.random((20000, 2))
    done = threading.Event()
    ticks = []

    def build():
        dynmesh.Mesh(points)
        done.set()

    t = threading.Thread(target=build)
    t.start()
    while not done.is_set():
        ticks.append(1)
        done.wait(0.001)
    t.join()
    assert len(ticks) > 10  # it ran on while the build held no GIL
