#!/usr/bin/env bash
# stability_experiments.sh — the trace-distance experiments of docs/EXPERIMENTS.md.
#
# Runs `dynmesh stability` (docs/FORMATS.md) over
#   1. spread: `shrinking` at n = 4096 with L/s = 2^8 ... 2^40, 2D and 3D;
#   2. the other distributions (uniform, clusters, spiral), whose spread grows with n,
#      at n = 1000 ... 64000, 2D;
#   3. size: `shrinking` at L/s = 2^20, n = 10^3, 10^4, 10^5, 2D and 3D;
# then fits trace distance = a + b·log2(L/s) per distribution (least squares over every
# measured update), tabulates the mean distance and update time per n, and draws two
# gnuplot pictures. Everything lands in docs/data/ and docs/figures/; the tables are
# printed as Markdown for docs/EXPERIMENTS.md.
#
# With `--postprocess quadtree` (or hpu) the same experiments measure the whole update of
# the 2D quadtree mesh (or the hpu mesh; DynamicMesh: tree and mesh in one trace), into
# docs/data/mesh_* and docs/figures/mesh_* (hpu: hpu_*); the spread sweep stops at 2^36,
# the deepest a mesh of derived-box coordinates resolves (mesh_resolution_level).
#
# With `--postprocess quadtree --dim 3` they measure the octree's tetrahedral mesh
# (DynamicOctreeMesh), into docs/data/mesh3d_* and docs/figures/mesh3d_*, on a smaller plan
# (an update costs more, and each run's final check builds a from-scratch OctreeMesh, whose
# tetrahedra, about 1,450 a uniform point at 96 bytes each, set the peak: 4.6 GB for
# uniform 16000, 7.5 GB for the largest run at 16000): 100 updates a run; the spread sweep
# `shrinking` at n = 2000 with L/s = 2^5 ... 2^30; uniform and clusters at n = 1000, 4000,
# 16000 (and 64000 and 10^5 with MESH3D_LARGE=1, for a machine with the memory: 20 to 30 GB
# at 64000); size at L/s = 2^20, n = 1000 ... 16000.
#
# Usage: bash bench/stability_experiments.sh [--quick] [--postprocess quadtree|hpu] [--dim 3]
# It first brings build/release's `dynmesh` up to date with the sources (the Release build
# of `bash dev.sh run`), so the figures are those of the tree checked out. DYNMESH=PATH runs
# that binary instead, as it is. Either way the binary and its age go to stderr.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
if [[ -n ${DYNMESH:-} ]]; then
  BIN=$DYNMESH
else
  BIN=build/release/bin/dynmesh
  # Configured as dev.sh does when there is no build yet; an existing one keeps its generator.
  [[ -f build/release/CMakeCache.txt ]] ||
    cmake -S "$ROOT" -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
  cmake --build build/release --target dynmesh_cli > /dev/null
fi
[[ -x $BIN ]] || { echo "$0: no dynmesh binary at $BIN" >&2; exit 2; }
echo "$0: measuring $BIN, built $(date -r "$BIN" '+%F %T')" >&2
DATA=docs/data
FIG=docs/figures
mkdir -p "$DATA" "$FIG"
QUICK=0
PP=none
DIM=2
while (($#)); do
  case $1 in
    --quick) QUICK=1 ;;
    --postprocess) PP=${2:?--postprocess needs a value}; shift ;;
    --dim) DIM=${2:?--dim needs a value}; shift ;;
    *) echo "usage: $0 [--quick] [--postprocess quadtree|hpu] [--dim 3]" >&2; exit 2 ;;
  esac
  shift
done
[[ $DIM == 2 || ($DIM == 3 && $PP == quadtree) ]] ||
  { echo "$0: --dim 3 measures the octree mesh (--postprocess quadtree)" >&2; exit 2; }
U=400
((QUICK)) && U=60
# The plan: spread sweep (n, exponents), distributions (which, sizes), size series (sizes).
SPREAD_N=4096 SPREAD_KS="8 12 16 20 24 28 32 36 40" DISTS="uniform clusters spiral"
DIST_NS="1000 4000 16000 64000" SIZE_NS="1000 10000 100000" QUICK_MOD=8
if [[ $PP == none ]]; then
  P=stability_ FP= DIMS="2 3" KMAX=40 PPARGS=() WHAT="the quadtree"
elif [[ $PP == quadtree && $DIM == 3 ]]; then
  P=mesh3d_stability_ FP=mesh3d_ DIMS=3 KMAX=30 PPARGS=(--postprocess "$PP") WHAT="the octree mesh"
  U=100
  ((QUICK)) && U=30
  SPREAD_N=2000 SPREAD_KS="5 10 15 20 25 30" QUICK_MOD=10 DISTS="uniform clusters" SIZE_NS="1000 4000 16000"
  DIST_NS="1000 4000 16000"
  [[ ${MESH3D_LARGE:-0} == 1 ]] && DIST_NS+=" 64000 100000"
elif [[ $PP == quadtree ]]; then
  P=mesh_stability_ FP=mesh_ DIMS=2 KMAX=36 PPARGS=(--postprocess "$PP") WHAT="the $PP mesh"
else
  P=hpu_stability_ FP=hpu_ DIMS=2 KMAX=36 PPARGS=(--postprocess "$PP") WHAT="the $PP mesh"
fi

SPREAD_CSV=$DATA/${P}spread.csv
DIST_CSV=$DATA/${P}distributions.csv
SIZE_CSV=$DATA/${P}size.csv
rm -f "$SPREAD_CSV" "$DIST_CSV" "$SIZE_CSV"

RUNS=$DATA/${FP}run_means.dat  # one line per run: series log2_spread mean_distance n mean_us
rm -f "$RUNS"
# run ARGS...: one `dynmesh stability` run; its rows are the last U of the CSV (the last
# argument), whose means go to $RUNS.
run() {
  echo "+ $BIN stability $* ${PPARGS[*]}" >&2
  "$BIN" stability "$@" "${PPARGS[@]}"
  local csv=${*: -1}
  tail -n "$U" "$csv" | awk -F, '{ x += $4; y += $6; t += $7; k++; s = $1 "-" $2 "d"; n = $3 }
    END { printf "%s %.3f %.2f %s %.2f\n", s, x / k, y / k, n, t / k * 1e6 }' >> "$RUNS"
}

# 1. Trace distance against the spread, at fixed n.
for dim in $DIMS; do
  for k in $SPREAD_KS; do
    ((k > KMAX)) && continue
    ((QUICK)) && ((k % QUICK_MOD != 0)) && continue
    run --dim $dim --dist shrinking --n $SPREAD_N --spread $((2 ** k)) --updates $U --seed 1 --csv "$SPREAD_CSV"
  done
done

# 2. The other distributions: their spread comes with n.
for dist in $DISTS; do
  for n in $DIST_NS; do
    ((QUICK)) && ((n > 4000)) && continue
    run --dim $DIM --dist $dist --n $n --updates $U --seed 1 --csv "$DIST_CSV"
  done
done

# 3. No dependence on n at a fixed spread.
for dim in $DIMS; do
  for n in $SIZE_NS; do
    ((QUICK)) && ((n > 10000)) && continue
    run --dim $dim --dist shrinking --n $n --spread $((2 ** 20)) --updates $U --seed 1 --csv "$SIZE_CSV"
  done
done

# ---------------------------------------------------------------- tables
echo
echo "### Fit: trace distance = a + b · log2(L/s), least squares over every update"
echo
echo "| data | dist | dim | updates | log2(L/s) range | slope b | intercept a |"
echo "| --- | --- | --- | --- | --- | --- | --- |"
for f in "$SPREAD_CSV" "$DIST_CSV"; do
  awk -F, -v file="$(basename "$f")" 'FNR > 1 {
      k = $1 "," $2; n[k]++; x = $4; y = $6
      sx[k] += x; sy[k] += y; sxx[k] += x * x; sxy[k] += x * y
      if (!(k in lo) || x < lo[k]) lo[k] = x
      if (!(k in hi) || x > hi[k]) hi[k] = x }
    END { for (k in n) { split(k, p, ",")
      den = n[k] * sxx[k] - sx[k] * sx[k]
      b = den ? (n[k] * sxy[k] - sx[k] * sy[k]) / den : 0
      a = (sy[k] - b * sx[k]) / n[k]
      printf "| %s | %s | %s | %d | %.1f – %.1f | %.1f | %.1f |\n", file, p[1], p[2], n[k], lo[k], hi[k], b, a } }' "$f" | sort
done

echo
echo "### Per run: trace distance and update time (spread sweep, then the distributions)"
echo
echo "| dist | dim | n | log2(L/s) first update | updates | mean distance | median distance | max distance | mean update (µs) | median update (µs) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for f in "$SPREAD_CSV" "$DIST_CSV"; do
  # A run is a block of rows with one (dist, dim, n) after a change of the spread's start.
  awk -F, 'function flush(   i, j, x, m, md, mt) {
      if (!k) return
      m = k
      for (i = 2; i <= m; i++) { x = d[i]; j = i - 1; while (j > 0 && d[j] > x) { d[j + 1] = d[j]; j-- } d[j + 1] = x }
      for (i = 2; i <= m; i++) { x = t[i]; j = i - 1; while (j > 0 && t[j] > x) { t[j + 1] = t[j]; j-- } t[j + 1] = x }
      md = m % 2 ? d[(m + 1) / 2] : (d[m / 2] + d[m / 2 + 1]) / 2
      mt = m % 2 ? t[(m + 1) / 2] : (t[m / 2] + t[m / 2 + 1]) / 2
      printf "| %s | %s | %s | %.2f | %d | %.1f | %.1f | %d | %.1f | %.1f |\n", key1, key2, key3, s0, m, sd / m, md, d[m], st / m * 1e6, mt * 1e6
      k = 0; sd = 0; st = 0 }
    FNR == 1 { flush(); next }
    { key = $1 "," $2 "," $3
      if (key != last || k >= '"$U"') { flush(); last = key; key1 = $1; key2 = $2; key3 = $3; s0 = $4 }
      k++; d[k] = $6 + 0; t[k] = $7 + 0; sd += $6; st += $7 }
    END { flush() }' "$f"
done

echo
echo "### Mean trace distance and update time against n (shrinking, L/s = 2^20)"
echo
echo "| dim | n | updates | mean trace distance | mean update (µs) | median update (µs) |"
echo "| --- | --- | --- | --- | --- | --- |"
awk -F, 'FNR > 1 { k = $2 "," $3; n[k]++; td[k] += $6; t[k] += $7; v[k] = v[k] " " $7 }
  END { for (k in n) { split(k, p, ","); m = split(v[k], a, " ")
      # median by insertion sort (a few hundred values)
      for (i = 2; i <= m; i++) { x = a[i]; j = i - 1; while (j > 0 && a[j] > x) { a[j + 1] = a[j]; j-- } a[j + 1] = x }
      med = m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
      printf "| %s | %s | %d | %.1f | %.1f | %.1f |\n", p[1], p[2], n[k], td[k] / n[k], t[k] / n[k] * 1e6, med * 1e6 } }' \
  "$SIZE_CSV" | sort -t'|' -k2,2n -k3,3n

# ---------------------------------------------------------------- pictures
# Per-run means (series, log2 spread, distance) for the spread plot; size means per dim.
grep -v '^shrinking' "$RUNS" > "$DATA/${FP}spread_means.dat" || true
# The spread sweep's runs are the shrinking runs at n = SPREAD_N.
awk -v n=$SPREAD_N '$1 ~ /^shrinking/ && $4 == n' "$RUNS" >> "$DATA/${FP}spread_means.dat"
sort -k1,1 -k2,2n -o "$DATA/${FP}spread_means.dat" "$DATA/${FP}spread_means.dat"
awk -F, 'FNR > 1 { k = $2 "d," $3; n[k]++; s[k] += $7; td[k] += $6 }
  END { for (k in n) { split(k, p, ","); print p[1], p[2], s[k] / n[k] * 1e6, td[k] / n[k] } }' "$SIZE_CSV" |
  sort -k1,1 -k2,2n > "$DATA/${FP}size_means.dat"

if command -v gnuplot >/dev/null; then
  series=$(cut -d' ' -f1 "$DATA/${FP}spread_means.dat" | sort -u)
  {
    echo "set terminal svg size 900,600 dynamic font 'sans,13'"
    echo "set output '$FIG/${FP}trace_distance_vs_spread.svg'"
    echo "set title 'Trace distance per update, $WHAT (mean of each run)'"
    echo "set xlabel 'log2(L/s)'; set ylabel 'trace events created + undone'"
    echo "set key right bottom; set grid; set yrange [0:*]"
    printf "plot "
    first=1
    for s in $series; do
      ((first)) || printf ", "
      first=0
      printf "'< grep \"^%s \" %s' using 2:3 with linespoints title '%s'" "$s" "$DATA/${FP}spread_means.dat" "$s"
    done
    # The mesh's figure also shows the tree alone (from a tree run of this script), dashed.
    if [[ -n $FP && -s $DATA/spread_means.dat ]]; then
      printf ", '< grep \"^shrinking-%sd \" %s' using 2:3 with linespoints dt 2 title 'shrinking-%sd, tree alone'" \
        "$DIM" "$DATA/spread_means.dat" "$DIM"
    fi
    echo
  } > "$DATA/${FP}spread.gp"
  gnuplot "$DATA/${FP}spread.gp"
  {
    echo "set terminal svg size 900,600 dynamic font 'sans,13'"
    echo "set output '$FIG/${FP}update_time_vs_n.svg'"
    echo "set title 'Update time and trace distance, $WHAT (shrinking, L/s = 2^{20})'"
    echo "set xlabel 'n'; set logscale x; set ylabel 'mean update time (µs)'; set y2label 'mean trace distance'"
    echo "set y2tics; set ytics nomirror; set key left bottom; set grid; set yrange [0:*]; set y2range [0:*]"
    printf "plot "
    first=1
    for dim in $DIMS; do
      ((first)) || printf ", "
      first=0
      printf "'< grep \"^%sd \" %s' using 2:3 with linespoints title '%sD time', " "$dim" "$DATA/${FP}size_means.dat" "$dim"
      printf "'< grep \"^%sd \" %s' using 2:4 axes x1y2 with linespoints dt 2 title '%sD distance'" \
        "$dim" "$DATA/${FP}size_means.dat" "$dim"
    done
    echo
  } > "$DATA/${FP}size.gp"
  gnuplot "$DATA/${FP}size.gp"
  echo
  echo "pictures: $FIG/${FP}trace_distance_vs_spread.svg $FIG/${FP}update_time_vs_n.svg"
else
  echo "gnuplot not found: no pictures (bash dev.sh deps installs it)" >&2
fi
