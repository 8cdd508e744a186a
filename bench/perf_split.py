#!/usr/bin/env python3
"""Split a perf profile of the self-adjusting hpu mesh's updates into geometry and runtime.

Reads `perf script -F comm,ip,sym,dso` output of a `perf record -g` run (a frame-pointer build,
e.g. `-DCMAKE_CXX_FLAGS="-g -fno-omit-frame-pointer"`) and keeps the samples under
sac::Engine::propagate (change propagation: the updates, not the first run). Each is
counted as:
  - questions: a frame of CellQuestions (the cell geometry: star walks, left searches,
    nearest searches, loose tests, and the view's searches they make);
  - kernel: a leaf frame in the kernel ([kernel.kallsyms]);
  - runtime and glue: the rest (the engine's matching, undo, reads, writes, the order list,
    the view's bookkeeping around the questions, the program's own steps).
It also prints the share of the samples under a left search (CellQuestions::left_search: the
star walks' steps, most of them), the part that stars held by the cells would cut. Then the
leaf functions of the runtime part, most frequent first. With --scratch it keeps the samples
of the first run instead (under sac::Engine::drain and not under propagate).

  perf record -g -o u.data build/relg/bin/dynmesh_hpu_steps --dist uniform --n 32000 --updates 3000
  perf script -i u.data -F comm,ip,sym,dso > u.txt && python3 bench/perf_split.py u.txt [--top 15]
"""
import argparse
import collections
import re
import sys


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("file", nargs="?", help="perf script output (default: standard input)")
    ap.add_argument("--top", type=int, default=15, help="runtime leaf functions to list")
    ap.add_argument("--scratch", action="store_true", help="the first run's samples instead of the updates'")
    args = ap.parse_args()
    if args.file:
        with open(args.file, encoding="utf-8", errors="replace") as f:
            text = f.read()
    else:
        text = sys.stdin.read()
    total = under = 0
    split = collections.Counter()
    leaves = collections.Counter()
    for block in text.split("\n\n"):
        lines = [line.strip() for line in block.strip().split("\n")[1:]]
        if not lines:
            continue
        total += 1
        # "ip symbol (dso)": the symbol without its dso, which names the kernel's frames.
        syms = [re.sub(r" \([^()]*\)$", "", line.split(" ", 1)[1]) if " " in line else "" for line in lines]
        in_kernel = "kernel.kallsyms" in lines[0]
        updating = any("Engine::propagate" in s for s in syms)
        if args.scratch == updating or (args.scratch and not any("Engine::drain" in s for s in syms)):
            continue
        under += 1
        if any("CellQuestions" in s and "left_search" in s for s in syms):
            split["left searches"] += 1
        if any("CellQuestions" in s for s in syms):
            split["questions"] += 1
        elif in_kernel:
            split["kernel"] += 1
        else:
            split["runtime and glue"] += 1
            leaves[re.sub(r"<.*", "", syms[0])[:100]] += 1
    where = "in the first run" if args.scratch else "under propagate"
    if not under:
        sys.exit(f"perf_split: no sample {where} (a -g profile of a frame-pointer build?)")
    print(f"samples {total}, {where} {under}")
    for k in ("questions", "runtime and glue", "kernel"):
        print(f"{100 * split[k] / under:5.1f}%  {k}")
    print(f"{100 * split['left searches'] / under:5.1f}%  left searches (part of the questions)")
    rt = split["runtime and glue"]
    if rt:
        print("runtime and glue, by leaf function (share of that part):")
        for name, n in leaves.most_common(args.top):
            print(f"{100 * n / rt:5.1f}%  {name}")


if __name__ == "__main__":
    main()
