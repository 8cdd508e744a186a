#!/usr/bin/env python3
"""Points of a cluster far below the box's scale, and an edit script, for `dynmesh mesh`.

Writes OUT.pts (plain `x y` lines) and OUT.edits (`+ x y` / `- x y` lines): `--cluster`
points uniform over a disc of radius `--radius` around (0.3, 0.7), `--uniform` points
uniform over [0.001, 0.999]^2, and `--edits` edits that delete present points (mostly in
the cluster), put deleted ones back, or insert points held back from the uniform ones.
Every point lies in the unit box, so mesh with `--box 0 0 1`. The same arguments give the
same files. Example (bench/RESULTS.md, "Clusters far below the box's scale"):

    python3 bench/deep_cluster.py --radius 1e-11 -o /tmp/cluster_1e-11
    build/release/bin/dynmesh mesh /tmp/cluster_1e-11.pts --box 0 0 1 \
        --edits /tmp/cluster_1e-11.edits -o /tmp/out --stats
"""
import argparse
import math
import random


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--radius", type=float, default=1e-11, help="the cluster's radius (box side 1)")
    ap.add_argument("--cluster", type=int, default=2700, help="points in the cluster")
    ap.add_argument("--uniform", type=int, default=300, help="points spread over the box")
    ap.add_argument("--edits", type=int, default=150, help="edits in the script")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("-o", dest="out", required=True, help="output base: OUT.pts and OUT.edits")
    a = ap.parse_args()
    if not 0 < a.radius < 0.29 or a.cluster < 0 or a.uniform < 0 or a.edits < 0:
        ap.error("need 0 < radius < 0.29 and non-negative counts")

    rng = random.Random(a.seed)
    pts = []
    for _ in range(a.cluster):
        r, t = a.radius * math.sqrt(rng.random()), 2 * math.pi * rng.random()
        pts.append((0.3 + r * math.cos(t), 0.7 + r * math.sin(t)))
    pts += [(rng.uniform(0.001, 0.999), rng.uniform(0.001, 0.999)) for _ in range(a.uniform)]
    pts = list(dict.fromkeys(pts))  # no duplicates
    held = min(len(pts) // 4, a.edits)  # uniform points kept back for insertions
    present, pool = pts[: len(pts) - held], pts[len(pts) - held :]

    deleted, edits, live = [], [], list(present)
    for _ in range(a.edits):
        u = rng.random()
        if u < 0.4 and live:
            p = live.pop(rng.randrange(len(live)))
            deleted.append(p)
            edits.append(("-", p))
        elif u < 0.7 and deleted:
            p = deleted.pop()
            live.append(p)
            edits.append(("+", p))
        elif pool:
            p = pool.pop()
            live.append(p)
            edits.append(("+", p))

    with open(a.out + ".pts", "w") as f:
        f.writelines(f"{x!r} {y!r}\n" for x, y in present)
    with open(a.out + ".edits", "w") as f:
        f.writelines(f"{op} {x!r} {y!r}\n" for op, (x, y) in edits)
    print(f"{a.out}.pts: {len(present)} points; {a.out}.edits: {len(edits)} edits")


if __name__ == "__main__":
    main()
