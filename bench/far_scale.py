#!/usr/bin/env python3
"""Uniform points and an edit script in a box of side 2^E, for `dynmesh mesh`.

Writes OUT.pts (plain `x y` lines) and OUT.edits (`+ x y` / `- x y` lines): `--n` points
uniform over [0, 1)^2 and `--edits` edits (each pair deletes the next of the first points,
then inserts a new uniform point), every coordinate multiplied by 2^E. The product is exact
for every E the script accepts (random() gives multiples of 2^-53, so none becomes
subnormal), and 17 significant digits read back to the same double, so the files for every
E hold the same points, scaled. Mesh with `--box 0 0 2^E` (the script prints it). The same
arguments give the same files. Example (bench/RESULTS.md, "Coordinates far from the unit scale"):

    python3 bench/far_scale.py --exp 963 -o /tmp/far963
    build/release/bin/dynmesh mesh /tmp/far963.pts --box 0 0 7.79625120912e+289 \
        --edits /tmp/far963.edits -o /tmp/out --stats
"""
import argparse
import math
import random


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--exp", type=int, default=0, help="E: the box's side is 2^E")
    ap.add_argument("--n", type=int, default=2000, help="points")
    ap.add_argument("--edits", type=int, default=200, help="edits in the script (even)")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("-o", dest="out", required=True, help="output base: OUT.pts and OUT.edits")
    a = ap.parse_args()
    if not -969 <= a.exp <= 1000 or a.n < 1 or a.edits < 0 or a.edits // 2 > a.n:
        ap.error("need -969 <= exp <= 1000, n >= 1 and edits / 2 <= n")

    rng = random.Random(a.seed)
    pts = list(dict.fromkeys((rng.random(), rng.random()) for _ in range(a.n)))
    edits = []
    for i in range(a.edits // 2):
        edits.append(("-",) + pts[i])
        edits.append(("+", rng.random(), rng.random()))
    s = math.ldexp(1.0, a.exp)
    with open(a.out + ".pts", "w") as f:
        f.writelines("%.17g %.17g\n" % (x * s, y * s) for x, y in pts)
    with open(a.out + ".edits", "w") as f:
        f.writelines("%s %.17g %.17g\n" % (op, x * s, y * s) for op, x, y in edits)
    print("box: --box 0 0 %r" % s)


if __name__ == "__main__":
    main()
