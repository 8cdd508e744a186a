#!/usr/bin/env bash
# tests/cli/cli_test.sh CASE DYNMESH DATA_DIR WORK_DIR — end-to-end tests of the `dynmesh`
# command (docs/FORMATS.md contracts), one ctest per CASE (see tests/cli/CMakeLists.txt).
# Exit 0 pass, 1 fail, 77 skipped (ctest SKIP_RETURN_CODE).
set -uo pipefail

case_name=$1 dynmesh=$2 data=$3 work=$4
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
# No progress lines unless a case asks for them: in a slow build (sanitizers, SAC_DEBUG_CHECKS)
# a run passes the one-second delay and its progress line would break the one-line checks of
# stderr. Set unconditionally: a shell that exported 0 to watch the lines would otherwise fail
# most cases. The progress case sets its own delays.
export DYNMESH_PROGRESS_DELAY_MS=3600000

fail() {
  echo "FAIL [$case_name]: $*" >&2
  exit 1
}

# run CMD...: must exit 0; stdout in out.txt, stderr in err.txt.
run() {
  "$@" >out.txt 2>err.txt
  local rc=$?
  ((rc == 0)) || { cat err.txt >&2; fail "exit status $rc: $*"; }
}

# expect_error WANT_STATUS WANT_TEXT CMD...: must exit WANT_STATUS with exactly one line on
# stderr, of the form "dynmesh: ...", containing WANT_TEXT (fixed string).
expect_error() {
  local want_status=$1 want=$2
  shift 2
  "$@" >out.txt 2>err.txt
  local rc=$?
  ((rc == want_status)) || { cat err.txt >&2; fail "exit status $rc, expected $want_status: $*"; }
  [[ $(wc -l <err.txt) -eq 1 ]] || { cat err.txt >&2; fail "stderr is not exactly one line: $*"; }
  grep -q '^dynmesh: ' err.txt || fail "stderr does not start with 'dynmesh: ': $(cat err.txt)"
  grep -qF -- "$want" err.txt || fail "stderr lacks '$want': $(cat err.txt)"
}

# box_of CELLS: the "o1 o2 [o3] L" of a .cells file's "# box" line (printed %.17g: exact).
box_of() { sed -n '3s/^# box //p' "$1"; }

# same_after_edits POINTS EDITS FINAL [--dim 3]: the .cells after the edits, propagated one by
# one, in batches of 3, and all at once, equal a from-scratch run on FINAL in the same box.
same_after_edits() {
  local points=$1 edits=$2 final=$3
  shift 3
  run "$dynmesh" quadtree "$points" "$@" --edits "$edits" --cells dyn.cells --check
  local box
  box=$(box_of dyn.cells)
  [[ -n $box ]] || fail "no box line in dyn.cells"
  # shellcheck disable=SC2086  # the box is several numbers
  run "$dynmesh" quadtree "$final" "$@" --box $box --cells scratch.cells --check
  cmp dyn.cells scratch.cells || fail "$edits: dynamic result differs from a from-scratch run on $final"
  run "$dynmesh" quadtree "$points" "$@" --edits "$edits" --batch 3 --cells batch3.cells --check
  cmp dyn.cells batch3.cells || fail "$edits: --batch 3 differs from single edits"
  run "$dynmesh" quadtree "$points" "$@" --edits "$edits" --batch 1000 --cells batchall.cells --check
  cmp dyn.cells batchall.cells || fail "$edits: one batch differs from single edits"
}

case $case_name in
  inputs) # every input kind builds and passes --check; the header records the dimension
    run "$dynmesh" quadtree "$data/points2d.node" --cells p2.cells --check
    grep -qx '# dim 2' p2.cells || fail "points2d.node: not 2D"
    head -1 p2.cells | grep -qx '# dynmesh cells v1' || fail "bad first line"
    run "$dynmesh" quadtree "$data/points3d.node" --cells p3.cells --check
    grep -qx '# dim 3' p3.cells || fail "points3d.node: the header's dimension was not used"
    run "$dynmesh" quadtree "$data/points3d.node" --dim 3 --cells p3b.cells --check
    cmp p3.cells p3b.cells || fail "--dim 3 on a 3D .node changes the result"
    run "$dynmesh" quadtree "$data/scan.xyz" --dim 3 --cells xyz.cells --check
    grep -qx '# dim 3' xyz.cells || fail "scan.xyz --dim 3: not 3D"
    run "$dynmesh" quadtree "$data/scan.xyz" --dim 2 --cells xyz2.cells --check  # first two columns
    grep -qx '# dim 2' xyz2.cells || fail "scan.xyz --dim 2: not 2D"
    run "$dynmesh" quadtree "$data/boundary.txt" --box 0 0 1 --cells boundary.cells --check
    grep -qx '# box 0 0 1' boundary.cells || fail "--box not recorded exactly"
    run "$dynmesh" quadtree "$data/boundary.txt" --cells boundary2.cells --check
    run "$dynmesh" quadtree "$data/collinear.txt" --cells collinear.cells --check
    run "$dynmesh" quadtree "$data/grid.txt" --cells grid.cells --check
    run "$dynmesh" quadtree "$data/final3d.txt" --dim 3 --cells f3.cells --check
    run "$dynmesh" quadtree "$data/final3d.txt" --cells f3b.cells --check # x y z lines: 3D without --dim
    cmp f3.cells f3b.cells || fail "final3d.txt without --dim is not its 3D tree"
    # One leaf line per leaf after the three header lines, sorted by (level, i, j).
    tail -n +4 grid.cells | sort -n -k1,1 -k2,2 -k3,3 -c || fail "grid.cells is not sorted"
    ;;

  edits2d)
    same_after_edits "$data/points2d.node" "$data/edits2d.txt" "$data/final2d.txt"
    ;;

  edits3d)
    same_after_edits "$data/points3d.node" "$data/edits3d.txt" "$data/final3d.txt" --dim 3
    ;;

  errors) # one line on stderr naming file and line; exit 1; no output file
    expect_error 1 'bad_number.txt:3: ' "$dynmesh" quadtree "$data/bad_number.txt" --cells e.cells
    expect_error 1 'nan.txt:4: ' "$dynmesh" quadtree "$data/nan.txt" --cells e.cells
    expect_error 1 'duplicate.txt:5: ' "$dynmesh" quadtree "$data/duplicate.txt" --cells e.cells
    expect_error 1 'resolution.txt:4: ' "$dynmesh" quadtree "$data/resolution.txt" --cells e.cells
    grep -qF '(lines 2, 4)' err.txt || fail "resolution: both lines not named: $(cat err.txt)"
    expect_error 1 'outside.txt:4: ' "$dynmesh" quadtree "$data/outside.txt" --box 0 0 1 --cells e.cells
    # Edit errors, propagating one edit at a time and in batches of 2.
    for batch in "" "--batch 2"; do
      # shellcheck disable=SC2086  # $batch is zero or two words
      edit() { "$dynmesh" quadtree "$data/points2d.node" --edits "$data/$1" $batch --cells e.cells; }
      expect_error 1 'edits_absent.txt:3: ' edit edits_absent.txt
      grep -q 'not in the set' err.txt || fail "absent point: unclear message: $(cat err.txt)"
      expect_error 1 'edits_present.txt:2: ' edit edits_present.txt
      expect_error 1 'edits_outside.txt:3: ' edit edits_outside.txt
    done
    [[ ! -e e.cells ]] || fail "a failed run wrote its output file"
    expect_error 1 'cannot open' "$dynmesh" quadtree "$data/no-such-file.txt" --cells e.cells
    expect_error 1 'draws 2D trees only' "$dynmesh" quadtree "$data/points3d.node" --cells e.cells --svg e.svg
    expect_error 1 'points3d.node:1: ' "$dynmesh" quadtree "$data/points3d.node" --dim 2 --cells e.cells
    expect_error 1 '--box' "$dynmesh" quadtree "$data/grid.txt" --box 0 0 0 1 --cells e.cells
    expect_error 2 '--cells' "$dynmesh" quadtree "$data/grid.txt"
    expect_error 2 '--batch' "$dynmesh" quadtree "$data/grid.txt" --cells e.cells --batch 0
    expect_error 1 'unknown distribution' "$dynmesh" stability --dim 2 --dist nope --n 10 --csv e.csv
    ;;

  stability)
    header='dist,dim,n,log2_spread,op,trace_distance,seconds'
    run "$dynmesh" stability --dim 2 --dist uniform --n 300 --updates 30 --csv s.csv
    [[ $(head -1 s.csv) == "$header" ]] || fail "CSV header: $(head -1 s.csv)"
    [[ $(wc -l <s.csv) -eq 31 ]] || fail "expected header + 30 rows, got $(wc -l <s.csv) lines"
    run "$dynmesh" stability --dim 3 --dist shrinking --n 300 --spread 4096 --updates 20 --seed 5 --csv s.csv
    [[ $(wc -l <s.csv) -eq 51 ]] || fail "append: expected header + 50 rows, got $(wc -l <s.csv) lines"
    [[ $(grep -c '^dist,' s.csv) -eq 1 ]] || fail "header written twice"
    # Every row: 7 fields, op insert|delete, integer trace distance, the run's dist/dim/n.
    tail -n +2 s.csv | awk -F, 'NF != 7 || ($5 != "insert" && $5 != "delete") || $6 !~ /^[0-9]+$/ ||
      !(($1 == "uniform" && $2 == 2 && $3 == 300) || ($1 == "shrinking" && $2 == 3 && $3 == 300)) { bad = 1; print }
      END { exit bad }' || fail "malformed rows"
    [[ $(grep -c ',delete,' s.csv) -eq 25 && $(grep -c ',insert,' s.csv) -eq 25 ]] || fail "not half deletions"
    # --postprocess quadtree: the same updates (same seed) measured through tree and mesh, so
    # every row's trace distance includes the tree's, and the run verifies the final mesh.
    run "$dynmesh" stability --dim 2 --dist clusters --n 400 --updates 40 --seed 3 --csv tree.csv
    run "$dynmesh" stability --dim 2 --dist clusters --n 400 --updates 40 --seed 3 --postprocess quadtree \
      --min-angle 18.4 --csv mesh.csv
    grep -q 'quadtree mesh, clusters 2D' out.txt || fail "the mesh run did not say it measured the mesh"
    [[ $(wc -l <mesh.csv) -eq 41 ]] || fail "mesh CSV: expected header + 40 rows"
    paste -d, <(tail -n +2 tree.csv) <(tail -n +2 mesh.csv) | awk -F, '$4 != $11 || $5 != $12 || $13 <= $6 { bad = 1; print }
      END { exit bad }' || fail "mesh rows do not follow the tree rows (same ops and spreads, larger distances)"
    # --postprocess hpu: the same updates through the tree and the hpu mesh, verified against
    # a from-scratch HpuMesh at the end.
    run "$dynmesh" stability --dim 2 --dist clusters --n 400 --updates 40 --seed 3 --postprocess hpu \
      --min-angle 25 --csv hpu.csv
    grep -q 'hpu mesh, clusters 2D' out.txt || fail "the hpu run did not say it measured the hpu mesh"
    [[ $(wc -l <hpu.csv) -eq 41 ]] || fail "hpu CSV: expected header + 40 rows"
    paste -d, <(tail -n +2 tree.csv) <(tail -n +2 hpu.csv) | awk -F, '$4 != $11 || $5 != $12 || $13 <= $6 { bad = 1; print }
      END { exit bad }' || fail "hpu rows do not follow the tree rows (same ops and spreads, larger distances)"
    expect_error 2 '--min-angle for hpu must be between 1 and 30 degrees, got 31' "$dynmesh" stability --dim 2 \
      --dist uniform --n 50 --postprocess hpu --min-angle 31 --csv e.csv
    expect_error 2 '--postprocess hpu is 2D only' "$dynmesh" stability --dim 3 --dist uniform --n 50 \
      --postprocess hpu --csv e.csv
    expect_error 2 '--min-angle is 2D only' "$dynmesh" stability --dim 3 --dist uniform --n 50 \
      --postprocess quadtree --min-angle 10 --csv e.csv
    expect_error 2 '--min-angle needs a mesh' "$dynmesh" stability --dim 2 --dist uniform --n 50 --min-angle 10 \
      --csv e.csv
    expect_error 2 'above the quadtree' "$dynmesh" stability --dim 2 --dist uniform --n 50 --postprocess quadtree \
      --min-angle 30 --csv e.csv
    [[ ! -e e.csv ]] || fail "a refused stability run wrote its CSV"
    if command -v gnuplot >/dev/null; then
      run "$dynmesh" stability --dim 2 --dist clusters --n 300 --updates 10 --csv s.csv --plot plot.svg
      head -c 200 plot.svg | grep -q '<svg\|<?xml' || fail "plot.svg is not SVG"
    else
      echo "gnuplot not installed: --plot not tested"
    fi
    ;;

  stability_points) # --points POINTS --edits FILE: one row per edit, dist = POINTS' base name
    header='dist,dim,n,log2_spread,op,trace_distance,seconds'
    edits=$(grep -c '^[+-]' "$data/edits2d.txt")
    grep '^[+-]' "$data/edits2d.txt" | cut -c1 >signs.txt # the edits' kinds, in order
    for pp in none quadtree hpu; do
      run "$dynmesh" stability --points "$data/points2d.node" --edits "$data/edits2d.txt" --postprocess $pp \
        --csv $pp.csv
      [[ $(head -1 $pp.csv) == "$header" ]] || fail "$pp: CSV header: $(head -1 $pp.csv)"
      [[ $(wc -l <$pp.csv) -eq $((edits + 1)) ]] || fail "$pp: expected header + $edits rows, got $(wc -l <$pp.csv)"
      # Every row: points2d, 2D, n = 50 (the initial points), op the edit's kind, distance > 0.
      paste -d, <(tail -n +2 $pp.csv) signs.txt | awk -F, 'NF != 8 || $1 != "points2d" || $2 != 2 || $3 != 50 ||
        !(($5 == "insert" && $8 == "+") || ($5 == "delete" && $8 == "-")) || $6 !~ /^[0-9]+$/ || $6 <= 0 ||
        $7 <= 0 { bad = 1; print } END { exit bad }' || fail "$pp: rows do not follow the edits"
      grep -q "points2d 2D, n = 50, .*, $edits edits, mean trace distance" out.txt || fail "$pp: summary: $(cat out.txt)"
    done
    grep -q '^stability: hpu mesh, points2d 2D' out.txt || fail "the hpu run did not say it measured the hpu mesh"
    # The same ops and spreads row by row. The quadtree mesh runs in the tree's trace, so each
    # of its edits costs more than the tree's alone; the hpu program has its own trace (an
    # edit may cost it less than the tree), so only its mean is compared.
    for pp in quadtree hpu; do
      paste -d, <(tail -n +2 none.csv) <(tail -n +2 $pp.csv) | awk -F, -v pp=$pp '$4 != $11 || $5 != $12 ||
        (pp == "quadtree" && $13 <= $6) { bad = 1; print } { a += $6; b += $13 } END { exit bad || b <= a }' ||
        fail "$pp rows do not follow the tree rows"
    done
    # The last row's log2_spread is log2(L/s) of the final points (final2d.txt), L the side of the
    # box derived from points2d.node, s their closest pair (brute force here).
    run "$dynmesh" quadtree "$data/points2d.node" --cells box.cells
    side=$(box_of box.cells | awk '{print $3}')
    want=$(grep -v '^#' "$data/final2d.txt" | awk -v L="$side" '{ x[NR] = $1; y[NR] = $2 }
      END { s = -1; for (i = 1; i <= NR; i++) for (j = i + 1; j <= NR; j++) {
        d = sqrt((x[i] - x[j]) ^ 2 + (y[i] - y[j]) ^ 2); if (s < 0 || d < s) s = d }
        printf "%.4f", log(L / s) / log(2) }')
    got=$(tail -1 none.csv | cut -d, -f4)
    awk -v a="$got" -v b="$want" 'BEGIN { exit !(a - b < 2e-4 && b - a < 2e-4) }' ||
      fail "last row's log2_spread $got, expected $want"
    # Appending works as with --dist: the old rows stay, the header is not repeated.
    cp none.csv saved.csv
    run "$dynmesh" stability --points "$data/points2d.node" --edits "$data/edits2d.txt" --csv none.csv
    cmp <(head -c "$(wc -c <saved.csv)" none.csv) saved.csv || fail "an append changed the old rows"
    [[ $(wc -l <none.csv) -eq $((2 * edits + 1)) && $(grep -c '^dist,' none.csv) -eq 1 ]] || fail "append"
    # 3D: a .node header decides the dimension; --box as quadtree takes it.
    edits3=$(grep -c '^[+-]' "$data/edits3d.txt")
    run "$dynmesh" stability --points "$data/points3d.node" --edits "$data/edits3d.txt" --csv d3.csv
    run "$dynmesh" stability --points "$data/points3d.node" --dim 3 --box -20 -20 -20 60 --edits "$data/edits3d.txt" \
      --csv d3.csv
    [[ $(wc -l <d3.csv) -eq $((2 * edits3 + 1)) ]] || fail "3D: expected header + $((2 * edits3)) rows"
    tail -n +2 d3.csv | awk -F, '$1 != "points3d" || $2 != 3 || $6 <= 0 { bad = 1; print } END { exit bad }' ||
      fail "3D rows"
    # A bad file: one line naming file and line, exit 1, and the CSV as it was.
    cp none.csv saved.csv
    { head -4 "$data/edits2d.txt"; echo '+ 1.5 x'; } >bad_edits.txt
    expect_error 1 'bad_edits.txt:5: ' "$dynmesh" stability --points "$data/points2d.node" --edits bad_edits.txt \
      --csv none.csv
    expect_error 1 'edits_absent.txt:3: ' "$dynmesh" stability --points "$data/points2d.node" \
      --edits "$data/edits_absent.txt" --postprocess hpu --csv none.csv
    grep -q 'not in the set' err.txt || fail "absent point: unclear message: $(cat err.txt)"
    expect_error 1 'edits_outside.txt:3: ' "$dynmesh" stability --points "$data/points2d.node" \
      --edits "$data/edits_outside.txt" --csv none.csv
    expect_error 1 'bad_number.txt:3: ' "$dynmesh" stability --points "$data/bad_number.txt" \
      --edits "$data/edits2d.txt" --csv none.csv
    expect_error 2 '--postprocess hpu is 2D only' "$dynmesh" stability --points "$data/points3d.node" \
      --edits "$data/edits3d.txt" --postprocess hpu --csv none.csv
    cmp none.csv saved.csv || fail "a failed run changed the CSV"
    expect_error 1 'bad_edits.txt:5: ' "$dynmesh" stability --points "$data/points2d.node" --edits bad_edits.txt \
      --csv new.csv
    [[ ! -e new.csv ]] || fail "a failed run wrote its CSV"
    if command -v gnuplot >/dev/null; then
      run "$dynmesh" stability --points "$data/points2d.node" --edits "$data/edits2d.txt" --csv none.csv --plot p.svg
      head -c 200 p.svg | grep -q '<svg\|<?xml' || fail "p.svg is not SVG"
    fi
    ;;

  stability_options) # --dist and --points exclude each other, and each its own options: exit 2
    p=(--points "$data/points2d.node" --edits "$data/edits2d.txt")
    expect_error 2 'excludes' "$dynmesh" stability "${p[@]}" --dist uniform --dim 2 --n 50 --csv e.csv
    grep -qF -- '--dist' err.txt && grep -qF -- '--points' err.txt || fail "the options are not named: $(cat err.txt)"
    for opt in "--n 50" "--spread 64" "--updates 10" "--seed 3"; do
      # shellcheck disable=SC2086  # $opt is two words
      expect_error 2 "${opt% *} excludes --points" "$dynmesh" stability "${p[@]}" $opt --csv e.csv
    done
    expect_error 2 '--points requires --edits' "$dynmesh" stability --points "$data/points2d.node" --csv e.csv
    expect_error 2 '--edits requires --points' "$dynmesh" stability --edits "$data/edits2d.txt" --dist uniform \
      --dim 2 --n 50 --csv e.csv
    expect_error 2 '--box requires --points' "$dynmesh" stability --dist uniform --dim 2 --n 50 --box 0 0 1 --csv e.csv
    expect_error 2 '--dist or --points is required' "$dynmesh" stability --dim 2 --n 50 --csv e.csv
    expect_error 2 '--dist requires --n' "$dynmesh" stability --dim 2 --dist uniform --csv e.csv
    expect_error 2 '--dist requires --dim' "$dynmesh" stability --dist uniform --n 50 --csv e.csv
    [[ ! -e e.csv ]] || fail "a refused run wrote its CSV"
    ;;

  curves) # the curves distribution, everywhere a distribution name is taken
    run "$dynmesh" stability --dim 2 --dist curves --n 400 --updates 20 --csv c.csv
    run "$dynmesh" stability --dim 3 --dist curves --n 300 --updates 10 --seed 2 --csv c.csv
    run "$dynmesh" stability --dim 2 --dist curves --n 400 --updates 10 --postprocess hpu --csv c.csv
    grep -q '^stability: hpu mesh, curves 2D' out.txt || fail "the hpu run: $(cat out.txt)"
    [[ $(wc -l <c.csv) -eq 41 ]] || fail "expected header + 40 rows, got $(wc -l <c.csv)"
    tail -n +2 c.csv | awk -F, '$1 != "curves" || $6 <= 0 { bad = 1; print } END { exit bad }' || fail "rows"
    "$dynmesh" stability --help >help.txt 2>&1
    grep -q 'boundary, curves' help.txt || fail "--help does not list curves: $(grep -- --dist help.txt)"
    ;;

  mesh_stats) # mesh --edits --stats: the quality report as before, then the propagations
    edits=$(grep -c '^[+-]' "$data/edits2d.txt")
    run "$dynmesh" quadtree "$data/points2d.node" --cells box.cells
    box=$(box_of box.cells)
    for pp in hpu quadtree; do
      # The quality report of the final mesh: the same lines as a from-scratch run's, first.
      # shellcheck disable=SC2086  # the box is several numbers
      run "$dynmesh" mesh "$data/final2d.txt" --postprocess $pp --box $box -o scratch --stats
      ! grep -q 'Propagation' err.txt || fail "$pp: propagation figures without --edits"
      cp err.txt quality.txt
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits "$data/edits2d.txt" -o dyn --stats
      cmp <(head -n "$(wc -l <quality.txt)" err.txt) quality.txt || fail "$pp: the quality report changed"
      tail -n +"$(($(wc -l <quality.txt) + 1))" err.txt >prop.txt
      [[ $(sed -n 2p prop.txt) == 'Propagation statistics:' ]] || fail "$pp: $(cat prop.txt)"
      grep -qx "  Propagations: $edits    Edits: $edits" prop.txt || fail "$pp: count: $(cat prop.txt)"
      grep -qE '^  Mean time: +[0-9.e+-]+ s +\|  Median time: +[0-9.e+-]+ s$' prop.txt || fail "$pp: times"
      grep -qE '^  Maximum time: +[0-9.e+-]+ s +\|  Mean trace distance: [1-9][0-9.e+]*$' prop.txt ||
        fail "$pp: maximum time, trace distance: $(cat prop.txt)"
      grep -qE '^  Mean triangles changed: [1-9][0-9.e+]* \(removed \+ added\)$' prop.txt ||
        fail "$pp: triangles changed: $(cat prop.txt)"
      # The maximum time is at least the median and the mean.
      awk '/Mean time:/ { mean = $3; median = $8 } /Maximum time:/ { max = $3 }
        END { exit !(max >= median && max >= mean && median > 0) }' prop.txt || fail "$pp: times: $(cat prop.txt)"
      # The mean triangles changed is that of the change feed.
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits "$data/edits2d.txt" -o dyn --feed f.feed \
        --stats
      want=$(awk '/^update / { t += $4 + $6; k++ } END { printf "%g", t / k }' f.feed)
      grep -qx "  Mean triangles changed: $want (removed + added)" err.txt || fail "$pp: not the feed's $want"
      # With --batch 3, one propagation per batch.
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits "$data/edits2d.txt" --batch 3 -o b --stats
      grep -qx "  Propagations: $(((edits + 2) / 3))    Edits: $edits" err.txt || fail "$pp --batch 3: $(cat err.txt)"
      # Without --stats, nothing on stderr.
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits "$data/edits2d.txt" -o q
      [[ ! -s err.txt ]] || fail "$pp: stderr without --stats: $(cat err.txt)"
    done
    ;;

  svg)
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells s.cells --svg tree.svg
    head -c 5 tree.svg | grep -q '^<?xml\|^<svg' || fail "tree.svg does not start like SVG"
    tail -1 tree.svg | grep -qx '</svg>' || fail "tree.svg is not closed"
    # 52 points after the edits, each drawn as one dot (none coincide at this scale).
    [[ $(grep -c '<circle' tree.svg) -eq $(grep -vc '^#' "$data/final2d.txt") ]] || fail "wrong number of dots"
    ;;

  demo)
    run "$dynmesh" demo --n 1000 --updates 100 --svg demo.svg
    grep -q '^verified: yes' out.txt || { cat out.txt; fail "demo not verified"; }
    grep -q 'trace distance' out.txt || fail "demo lacks the trace distance figure"
    # The first figure is the speedup of an update over re-meshing from scratch.
    sed -n 2p out.txt | grep -q '^  speedup  *[0-9]*x: an update vs re-meshing from scratch' ||
      fail "demo does not lead with the speedup over re-meshing: $(sed -n 2p out.txt)"
    grep -q '^  mesh  *[0-9]* vertices, [0-9]* triangles, smallest angle 2[0-9.]* degrees' out.txt ||
      fail "demo lacks the mesh figures (or its smallest angle is below 20): $(grep mesh out.txt)"
    grep -q '^  triangles changed' out.txt || fail "demo lacks the triangles changed per update"
    head -c 5 demo.svg | grep -q '^<?xml\|^<svg' || fail "demo.svg is not SVG"
    grep -q '<polygon\|<path\|<line' demo.svg || fail "demo.svg draws no mesh"
    ;;

  mesh_hpu) # the default postprocess: a quality Delaunay mesh, a function of the point set
    run "$dynmesh" mesh "$data/final2d.txt" -o hpu --check --stats --vtk hpu.vtk --svg hpu.svg
    [[ $(head -1 hpu.node | awk '{print $2, $3, $4}') == "2 0 1" ]] || fail "hpu.node header: $(head -1 hpu.node)"
    smallest=$(grep -o 'Smallest angle: *[0-9.]*' err.txt | awk '{print $3}')
    awk -v a="$smallest" 'BEGIN { exit !(a >= 20.7) }' || fail "smallest angle $smallest below 20.7"
    # The points reversed (and with --duplicates skip on a copy) give the same files.
    { grep '^#' "$data/final2d.txt"; grep -v '^#' "$data/final2d.txt" | tac; } >reversed.txt
    run "$dynmesh" mesh reversed.txt --postprocess hpu -o rev
    cmp hpu.node rev.node || fail "hpu: another point order gives another .node"
    cmp hpu.ele rev.ele || fail "hpu: another point order gives another .ele"
    for angle in 25 30; do
      run "$dynmesh" mesh "$data/final2d.txt" --min-angle "$angle" -o "a$angle" --check --stats
      smallest=$(grep -o 'Smallest angle: *[0-9.]*' err.txt | awk '{print $3}')
      awk -v a="$smallest" -v b="$angle" 'BEGIN { exit !(a >= b) }' || fail "smallest angle $smallest below $angle"
    done
    # More Steiner points at a higher bound.
    (($(head -1 a30.node | awk '{print $1}') > $(head -1 hpu.node | awk '{print $1}'))) ||
      fail "30 degrees did not add vertices over 20.7"
    # --edits: the self-adjusting hpu mesh gives the bytes of a from-scratch run on the final
    # points, one feed update per edit, and the same files with --batch.
    run "$dynmesh" quadtree "$data/points2d.node" --cells box.cells
    box=$(box_of box.cells)
    for angle in 20.7 30; do
      run "$dynmesh" mesh "$data/points2d.node" --min-angle "$angle" --edits "$data/edits2d.txt" -o "dyn$angle" \
        --check --feed "dyn$angle.feed"
      # shellcheck disable=SC2086  # the box is several numbers
      run "$dynmesh" mesh "$data/final2d.txt" --min-angle "$angle" --box $box -o "scratch$angle"
      cmp "dyn$angle.node" "scratch$angle.node" || fail "hpu $angle: dynamic .node differs from a from-scratch run"
      cmp "dyn$angle.ele" "scratch$angle.ele" || fail "hpu $angle: dynamic .ele differs from a from-scratch run"
    done
    edits=$(grep -c '^[+-]' "$data/edits2d.txt")
    [[ $(grep -c '^update ' dyn20.7.feed) -eq $edits ]] || fail "hpu feed: expected $edits updates"
    run "$dynmesh" mesh "$data/points2d.node" --edits "$data/edits2d.txt" --batch 3 -o batch3 --check
    cmp dyn20.7.node batch3.node || fail "hpu --batch 3 .node differs from single edits"
    cmp dyn20.7.ele batch3.ele || fail "hpu --batch 3 .ele differs from single edits"
    ;;

  mesh) # the quadtree mesh after edits equals a from-scratch mesh of the final points
    qt=(--postprocess quadtree)
    # The box derived from points2d.node, as `dynmesh quadtree` records it (same derivation).
    run "$dynmesh" quadtree "$data/points2d.node" --cells box.cells
    box=$(box_of box.cells)
    [[ -n $box ]] || fail "no box line in box.cells"
    run "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" --edits "$data/edits2d.txt" -o dyn --check \
      --feed dyn.feed --vtk dyn.vtk --msh dyn.msh --svg dyn.svg --stats
    for f in dyn.node dyn.ele dyn.feed dyn.vtk dyn.msh dyn.svg; do
      [[ -s $f ]] || fail "$f missing or empty"
    done
    [[ $(head -1 dyn.feed) == '# dynmesh feed v1' ]] || fail "feed header: $(head -1 dyn.feed)"
    # One update per edit, numbered from 1.
    edits=$(grep -c '^[+-]' "$data/edits2d.txt")
    [[ $(grep -c '^update ' dyn.feed) -eq $edits ]] || fail "feed: expected $edits updates"
    [[ $(grep -m1 '^update ' dyn.feed | cut -d' ' -f2) == 1 ]] || fail "feed: first update is not 1"
    grep -q 'Smallest angle' err.txt || fail "--stats printed no report: $(head -3 err.txt)"
    head -1 dyn.vtk | grep -q '^# vtk DataFile' || fail "dyn.vtk is not legacy VTK"
    [[ $(head -1 dyn.msh) == "\$MeshFormat" ]] || fail "dyn.msh is not MSH"
    tail -1 dyn.svg | grep -q '</svg>' || fail "dyn.svg is not closed"
    [[ $(head -1 dyn.node | cut -d' ' -f2-) == '2 0 1' ]] || fail "dyn.node header: $(head -1 dyn.node)"
    # shellcheck disable=SC2086  # the box is several numbers
    run "$dynmesh" mesh "$data/final2d.txt" "${qt[@]}" --box $box -o scratch --check
    cmp dyn.node scratch.node || fail "dynamic .node differs from a from-scratch run on final2d.txt"
    cmp dyn.ele scratch.ele || fail "dynamic .ele differs from a from-scratch run on final2d.txt"
    run "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" --edits "$data/edits2d.txt" --batch 3 -o batch3 \
      --feed batch3.feed --check
    cmp dyn.node batch3.node || fail "--batch 3 .node differs from single edits"
    cmp dyn.ele batch3.ele || fail "--batch 3 .ele differs from single edits"
    [[ $(grep -c '^update ' batch3.feed) -eq $(((edits + 2) / 3)) ]] || fail "--batch 3: wrong number of updates"
    run "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" --min-angle 18.4 -o plain --check
    ;;

  mesh_errors) # one line, exit 1, and the files of an earlier run left as they were
    qt=(--postprocess quadtree)
    run "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" -o old --feed old.feed
    cp old.node saved.node && cp old.ele saved.ele && cp old.feed saved.feed
    for batch in 0 2; do
      batch_args=()
      ((batch > 0)) && batch_args=(--batch "$batch")
      expect_error 1 'edits_absent.txt:3: ' "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" \
        --edits "$data/edits_absent.txt" "${batch_args[@]}" -o old --feed old.feed
      grep -q 'not in the set' err.txt || fail "absent point: unclear message: $(cat err.txt)"
      expect_error 1 'edits_outside.txt:3: ' "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" \
        --edits "$data/edits_outside.txt" "${batch_args[@]}" -o old
    done
    expect_error 1 'bad_number.txt:3: ' "$dynmesh" mesh "$data/bad_number.txt" "${qt[@]}" -o old
    expect_error 1 'duplicate.txt:5: ' "$dynmesh" mesh "$data/duplicate.txt" "${qt[@]}" -o old
    expect_error 2 'above the quadtree' "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" --min-angle 25 -o old
    # The hpu mesh (the default) reports bad edits as the quadtree mesh does.
    expect_error 1 'edits_absent.txt:3: ' "$dynmesh" mesh "$data/points2d.node" --edits "$data/edits_absent.txt" \
      -o old --feed old.feed
    expect_error 1 'edits_outside.txt:3: ' "$dynmesh" mesh "$data/points2d.node" --edits "$data/edits_outside.txt" \
      --batch 2 -o old
    for angle in 0.5 30.5; do
      expect_error 2 "--min-angle for hpu must be between 1 and 30 degrees, got $angle" "$dynmesh" mesh \
        "$data/points2d.node" --min-angle "$angle" -o old
    done
    expect_error 1 'duplicate.txt:5: ' "$dynmesh" mesh "$data/duplicate.txt" -o old
    expect_error 1 'points3d.node:1: ' "$dynmesh" mesh "$data/points3d.node" --dim 2 "${qt[@]}" -o old
    # An output that cannot be written: nothing else of the run is renamed into place.
    expect_error 1 'no-such-dir/x.svg' "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" \
      --edits "$data/edits2d.txt" -o old --svg no-such-dir/x.svg
    cmp old.node saved.node || fail "a failed run changed old.node"
    cmp old.ele saved.ele || fail "a failed run changed old.ele"
    cmp old.feed saved.feed || fail "a failed run changed old.feed"
    [[ -z $(find . -name '.*.tmp-*') ]] || fail "temporary files left behind: $(find . -name '.*.tmp-*')"
    expect_error 2 '-o' "$dynmesh" mesh "$data/points2d.node" "${qt[@]}"
    ;;

  feed_stream) # --feed streams to its temporary as the edits propagate (docs/FORMATS.md, "`dynmesh
    # mesh` (2D)"): the whole feed, byte for byte, and a run that fails midway (a bad edit, a
    # failed write, a target that is not a file) leaves the old files and no temporary.
    # many.txt moves every point of points2d.node a sixteenth of the way to (5, 5), eight
    # rounds, so that the feed passes the stream's buffer several times before the last edit.
    awk 'FNR > 2 && NF >= 3 { x[++n] = $2; y[n] = $3 }
      END { for (r = 1; r <= 8; r++) for (i = 1; i <= n; i++) {
              printf "- %.17g %.17g\n", x[i], y[i]; x[i] += (5 - x[i]) / 16; y[i] += (5 - y[i]) / 16
              printf "+ %.17g %.17g\n", x[i], y[i] } }' "$data/points2d.node" >many.txt
    edits=$(wc -l <many.txt)
    buffer=$((1 << 20)) # AtomicOutputs::Stream::kBufferBytes
    # tris_of NODE ELE: one sorted line per triangle, its corners as the .node writes them, in
    # the .ele's order: the form of the feed's lines.
    tris_of() {
      awk 'NR == FNR { if (FNR > 1) xy[$1] = $2 " " $3; next } FNR > 1 { print xy[$2], xy[$3], xy[$4] }' \
        "$1" "$2" | LC_ALL=C sort
    }
    # replay TRIS FEED: TRIS with every update's '-' lines removed and '+' lines added, in order;
    # fails when a removed triangle is absent or an added one is present.
    replay() {
      awk 'NR == FNR { have[$0] = 1; next }
        /^[-+] / { t = substr($0, 3); if ($1 == "-") { bad = bad || !(t in have); delete have[t] }
                   else { bad = bad || (t in have); have[t] = 1 } }
        END { for (t in have) print t; exit bad }' "$1" "$2" | LC_ALL=C sort
    }
    for pp in hpu quadtree; do
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits many.txt -o "$pp" --feed "$pp.feed" --check
      (($(wc -c <"$pp.feed") > 2 * buffer)) || fail "$pp.feed is too small to pass the stream's buffer"
      [[ $(head -1 "$pp.feed") == '# dynmesh feed v1' ]] || fail "$pp feed header: $(head -1 "$pp.feed")"
      [[ $(grep -c '^update ' "$pp.feed") -eq $edits ]] || fail "$pp feed: expected $edits updates"
      # The feed of the first edits, small enough to stay in the buffer until the end, is the
      # start of the whole feed, byte for byte.
      head -n 20 many.txt >first.txt
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits first.txt -o first --feed first.feed
      (($(wc -c <first.feed) < buffer)) || fail "first.feed does not fit in the buffer"
      cmp first.feed <(head -c "$(wc -c <first.feed)" "$pp.feed") || fail "$pp: the first edits' feed is not its start"
      # --batch 7: the same final mesh, one update per batch.
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp --edits many.txt --batch 7 -o batch7 \
        --feed batch7.feed
      cmp "$pp.node" batch7.node || fail "$pp: --batch 7 .node differs from single edits"
      cmp "$pp.ele" batch7.ele || fail "$pp: --batch 7 .ele differs from single edits"
      [[ $(grep -c '^update ' batch7.feed) -eq $(((edits + 6) / 7)) ]] || fail "$pp --batch 7: wrong number of updates"
      # Replayed on the initial mesh, each feed gives the final one.
      run "$dynmesh" mesh "$data/points2d.node" --postprocess $pp -o start
      tris_of start.node start.ele >start.tris
      tris_of "$pp.node" "$pp.ele" >final.tris
      for f in "$pp.feed" batch7.feed; do
        replay start.tris "$f" >replayed.tris || fail "$f removes an absent triangle or adds a present one"
        cmp replayed.tris final.tris || fail "$f replayed on the initial mesh does not give the final .ele"
      done
    done
    # A run that fails after the feed has passed the buffer: the old files as they were, no
    # temporary left.
    for f in node ele feed; do cp "hpu.$f" "saved.$f"; done
    unchanged() {
      for f in node ele feed; do cmp "hpu.$f" "saved.$f" || fail "$1: the failed run changed hpu.$f"; done
      [[ -z $(find . -name '.*.tmp-*') ]] || fail "$1: temporary files left behind: $(find . -name '.*.tmp-*')"
    }
    { cat many.txt; echo '- 1.2345 6.789'; } >absent.txt # the last edit deletes an absent point
    for batch in "" "--batch 7"; do
      # shellcheck disable=SC2086  # $batch is zero or two words
      expect_error 1 "absent.txt:$((edits + 1)): " "$dynmesh" mesh "$data/points2d.node" --edits absent.txt $batch \
        -o hpu --feed hpu.feed
      grep -q 'not in the set' err.txt || fail "absent point: unclear message: $(cat err.txt)"
      unchanged "absent point${batch:+ with $batch}"
    done
    # A write that fails midway (EFBIG under a file size limit of a quarter of the feed's
    # buffer, with SIGXFSZ ignored so that the write fails instead of the signal killing us).
    limited() (
      trap '' XFSZ
      ulimit -f $((buffer / 4096)) && exec "$@"
    )
    expect_error 1 'hpu.feed: cannot write output: write error: File too large' limited "$dynmesh" mesh \
      "$data/points2d.node" --edits many.txt -o hpu --feed hpu.feed
    unchanged "a failed write"
    # A target that is not a regular file is refused, not replaced.
    mkdir -p adir
    expect_error 1 'adir: cannot write output: not a regular file' "$dynmesh" mesh "$data/points2d.node" \
      --edits many.txt -o hpu --feed adir
    [[ -d adir ]] || fail "a directory target was replaced"
    unchanged "a directory target"
    ;;

  atomic) # a failed write (here EFBIG under a file size limit) names the OS reason and leaves
    # the old file byte for byte: quadtree .cells and --svg, mesh -o, the stability CSV and
    # --plot; an existing target that is not a regular file is refused, not replaced.
    # limited CMD...: CMD under a 1 KiB file size limit, with SIGXFSZ ignored so that the write
    # fails with EFBIG instead of the signal killing the process.
    limited() (
      trap '' XFSZ
      ulimit -f 1 && exec "$@"
    )
    qt=(--postprocess quadtree)
    run "$dynmesh" quadtree "$data/points2d.node" --cells old.cells --svg old.svg
    run "$dynmesh" mesh "$data/points2d.node" "${qt[@]}" -o old
    # The CSV stays below the limit, so that appending in place would write part of the rows.
    run "$dynmesh" stability --dim 2 --dist uniform --n 300 --updates 5 --csv old.csv
    (($(wc -c <old.csv) < 1024)) || fail "old.csv is not below the 1 KiB limit"
    cp old.csv saved.csv
    for f in old.cells old.svg old.node old.ele; do
      (($(wc -c <"$f") > 1024)) || fail "$f is too small to exceed the 1 KiB limit"
      cp "$f" "saved.${f#old.}"
    done
    # Without the limit these runs would succeed (and change every file).
    expect_error 1 'old.cells: cannot write output: write error: File too large' limited "$dynmesh" quadtree \
      "$data/points2d.node" --edits "$data/edits2d.txt" --cells old.cells --svg old.svg
    expect_error 1 'old.node: cannot write output: write error: File too large' limited "$dynmesh" mesh \
      "$data/points2d.node" "${qt[@]}" --edits "$data/edits2d.txt" -o old
    expect_error 1 'old.csv: cannot write output: write error: File too large' limited "$dynmesh" stability \
      --dim 2 --dist uniform --n 300 --updates 30 --seed 2 --csv old.csv
    for f in cells svg node ele csv; do cmp "old.$f" "saved.$f" || fail "a failed write changed old.$f"; done
    # The CSV append still appends when nothing fails.
    run "$dynmesh" stability --dim 2 --dist uniform --n 300 --updates 30 --seed 2 --csv old.csv
    cmp <(head -c "$(wc -c <saved.csv)" old.csv) saved.csv || fail "an append changed the old rows"
    [[ $(wc -l <old.csv) -eq 36 ]] || fail "append: expected header + 35 rows, got $(wc -l <old.csv) lines"
    if command -v gnuplot >/dev/null; then
      run "$dynmesh" stability --dim 2 --dist uniform --n 50 --updates 4 --csv p.csv --plot old.plot.svg
      cp old.plot.svg saved.plot.svg
      # A gnuplot that fails after writing half a picture.
      mkdir -p badplot
      cat >badplot/gnuplot <<'GNUPLOT'
#!/usr/bin/env bash
while IFS= read -r line; do
  if [[ $line == "set output '"*"'" ]]; then f=${line#set output \'}; echo '<svg' >"${f%\'}"; fi
done
exit 3
GNUPLOT
      chmod +x badplot/gnuplot
      expect_error 1 'gnuplot failed' env PATH="$PWD/badplot:$PATH" "$dynmesh" stability --dim 2 --dist uniform \
        --n 50 --updates 4 --csv p.csv --plot old.plot.svg
      cmp old.plot.svg saved.plot.svg || fail "a failed plot changed the old picture"
    fi
    mkdir -p adir
    expect_error 1 'adir: cannot write output: not a regular file' "$dynmesh" quadtree "$data/points2d.node" \
      --cells adir
    expect_error 1 'adir: cannot write output: not a regular file' "$dynmesh" stability --dim 2 --dist uniform \
      --n 50 --updates 2 --csv adir
    [[ -d adir ]] || fail "a directory target was replaced"
    [[ -z $(find . -name '.*.tmp-*' -o -name '.*.plot-*') ]] ||
      fail "temporary files left behind: $(find . -name '.*.tmp-*' -o -name '.*.plot-*')"
    ;;

  quirks) # a byte order mark, ',' and ';' separators; a directory or unreadable file named as such
    # The same points and edits with a BOM and list separators give the same tree and mesh.
    { printf '\xef\xbb\xbf'; awk '/^#/ { print; next } { print (NR % 2 ? $1 "," $2 : $1 "; " $2) }' \
      "$data/final2d.txt"; } >final2d.csv
    run "$dynmesh" quadtree "$data/final2d.txt" --cells plain.cells
    run "$dynmesh" quadtree final2d.csv --cells csv.cells --check
    cmp plain.cells csv.cells || fail "BOM and ',' / ';' separators: a different tree"
    run "$dynmesh" mesh "$data/final2d.txt" --postprocess quadtree -o plain
    run "$dynmesh" mesh final2d.csv --postprocess quadtree -o csv
    cmp plain.node csv.node || fail "BOM and ',' / ';' separators: a different mesh"
    { printf '\xef\xbb\xbf'; awk '/^[+-]/ { print $1 " " $2 "," $3; next } { print }' "$data/edits2d.txt"; } >edits.csv
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells e1.cells
    run "$dynmesh" quadtree "$data/points2d.node" --edits edits.csv --cells e2.cells
    cmp e1.cells e2.cells || fail "an edit script with a BOM and commas: a different tree"
    { printf '\xef\xbb\xbf'; cat "$data/points2d.node"; } >bom.node
    run "$dynmesh" quadtree "$data/points2d.node" --cells node.cells
    run "$dynmesh" quadtree bom.node --cells bom.cells
    cmp node.cells bom.cells || fail ".node with a BOM: a different tree"
    # Genuinely malformed lines keep their errors.
    expect_error 1 "decimal_comma.txt:3: malformed number '1,5'" "$dynmesh" quadtree "$data/decimal_comma.txt" \
      --cells e.cells
    printf '0.5,,0.25\n' >empty.csv
    expect_error 1 'empty.csv:1: empty field' "$dynmesh" quadtree empty.csv --cells e.cells
    printf '0,0\n1;nan\n' >nan.csv
    expect_error 1 "nan.csv:2: NaN or infinite coordinate 'nan'" "$dynmesh" quadtree nan.csv --cells e.cells
    # A directory, or a file that cannot be read, is named as such (not "read error").
    mkdir -p adir adir.node
    expect_error 1 'adir: cannot read: is a directory' "$dynmesh" quadtree adir --cells e.cells
    expect_error 1 'adir.node: cannot read: is a directory' "$dynmesh" quadtree adir.node --cells e.cells
    expect_error 1 'adir: cannot read: is a directory' "$dynmesh" mesh adir --postprocess quadtree -o e
    expect_error 1 'adir: cannot read: is a directory' "$dynmesh" quadtree "$data/grid.txt" --edits adir \
      --cells e.cells
    cp "$data/grid.txt" locked.txt && chmod 000 locked.txt
    if [[ $(id -u) -ne 0 ]]; then
      expect_error 1 'locked.txt: cannot open file: Permission denied' "$dynmesh" quadtree locked.txt --cells e.cells
    elif command -v setpriv >/dev/null && setpriv --reuid=65534 --regid=65534 --clear-groups test -x "$dynmesh"; then
      # root reads anything: run as nobody
      expect_error 1 'locked.txt: cannot open file: Permission denied' \
        setpriv --reuid=65534 --regid=65534 --clear-groups "$dynmesh" quadtree locked.txt --cells e.cells
    else
      echo "running as root without setpriv: the unreadable-file error is not tested"
    fi
    [[ ! -e e.cells && ! -e e.node ]] || fail "a failed run wrote its output file"
    ;;

  spread) # a spread beyond the resolution is reported as that, with L/s, naming the point
    # A far-out point stretches the derived box: it is named (line 6), not a "duplicate".
    for cmd in "quadtree --cells e.cells" "mesh --postprocess quadtree -o e"; do
      # shellcheck disable=SC2086  # $cmd is several words
      expect_error 1 'far_point.txt:6: point (1e+17, 4100000) makes the spread exceed the resolution' \
        "$dynmesh" $cmd "$data/far_point.txt"
      grep -q 'spread L/s = [0-9.e+]* (log2 5[0-9]\.[0-9]) with L = 3e+17' err.txt || fail "no spread: $(cat err.txt)"
      grep -qF 'the points on lines 3 and 4' err.txt || fail "the colliding pair is not named: $(cat err.txt)"
      ! grep -qi 'duplicate' err.txt || fail "misreported as a duplicate: $(cat err.txt)"
    done
    # Without such a point, the later point of the too-close pair, with both lines.
    expect_error 1 'resolution.txt:4: point (0, 9.0000000000000003e-16) makes the spread exceed the resolution' \
      "$dynmesh" quadtree "$data/resolution.txt" --cells e.cells
    grep -qF 'spread L/s = 3.33e+15 (log2 51.6) with L = 3 and s = 9e-16 (lines 2, 4)' err.txt ||
      fail "resolution.txt: $(cat err.txt)"
    expect_error 1 'resolution.txt:4: point (0, 9.0000000000000003e-16) makes the spread exceed the resolution' \
      "$dynmesh" mesh "$data/resolution.txt" --postprocess quadtree -o e
    # A pair the mesh cannot resolve at its coarser level, though the tree can.
    printf '0 0\n1 1\n0.5 0.5\n0.500000000001 0.5\n' >mesh_near.txt
    run "$dynmesh" quadtree mesh_near.txt --cells near.cells
    expect_error 1 'mesh_near.txt:4: point (0.50000000000099998, 0.5) makes the spread exceed the resolution L/2^' \
      "$dynmesh" mesh mesh_near.txt --postprocess quadtree -o e
    grep -qF '(lines 3, 4)' err.txt || fail "mesh_near.txt: the pair is not named: $(cat err.txt)"
    # Two points with one located position but different coordinates are not duplicates.
    printf '0 0\n1 1\n0.5 0.5\n1e-20 0\n' >same_q.txt
    expect_error 1 'same_q.txt:4: point (9.9999999999999995e-21, 0) makes the spread exceed the resolution' \
      "$dynmesh" quadtree same_q.txt --cells e.cells
    grep -qF '(log2 68.0)' err.txt || fail "same_q.txt: $(cat err.txt)"
    # Exact copies still are.
    expect_error 1 'duplicate.txt:5: duplicate point' "$dynmesh" quadtree "$data/duplicate.txt" --cells e.cells
    [[ ! -e e.cells && ! -e e.node ]] || fail "a failed run wrote its output file"
    ;;

  duplicates) # --duplicates error|skip
    awk '!seen[$0]++' "$data/duplicates_many.txt" >unique.txt
    run "$dynmesh" quadtree unique.txt --cells unique.cells
    run "$dynmesh" quadtree "$data/duplicates_many.txt" --duplicates skip --cells skip.cells --check
    grep -qx 'duplicates: skipped 2 later copies' out.txt || fail "quadtree skip count: $(cat out.txt)"
    cmp unique.cells skip.cells || fail "--duplicates skip: not the tree of the unique points"
    run "$dynmesh" quadtree unique.txt --duplicates skip --cells none.cells
    grep -qx 'duplicates: skipped 0 later copies' out.txt || fail "skip count without copies: $(cat out.txt)"
    run "$dynmesh" mesh unique.txt --postprocess quadtree -o unique
    run "$dynmesh" mesh "$data/duplicates_many.txt" --postprocess quadtree --duplicates skip -o skip --check
    grep -qx 'duplicates: skipped 2 later copies' out.txt || fail "mesh skip count: $(cat out.txt)"
    cmp unique.node skip.node && cmp unique.ele skip.ele || fail "--duplicates skip: not the mesh of the unique points"
    # error is the default.
    for policy in "" "--duplicates error"; do
      # shellcheck disable=SC2086  # $policy is zero or two words
      expect_error 1 'duplicates_many.txt:5: duplicate point' "$dynmesh" quadtree "$data/duplicates_many.txt" \
        $policy --cells e.cells
      # shellcheck disable=SC2086
      expect_error 1 'duplicates_many.txt:5: duplicate point' "$dynmesh" mesh "$data/duplicates_many.txt" \
        --postprocess quadtree $policy -o e
    done
    expect_error 2 '--duplicates' "$dynmesh" quadtree "$data/grid.txt" --duplicates drop --cells e.cells
    # skip drops copies only: a spread beyond the resolution is still an error, and so is an
    # edit that inserts a present point.
    expect_error 1 'far_point.txt:6: ' "$dynmesh" quadtree "$data/far_point.txt" --duplicates skip --cells e.cells
    expect_error 1 'edits_present.txt:2: ' "$dynmesh" quadtree "$data/points2d.node" --duplicates skip \
      --edits "$data/edits_present.txt" --cells e.cells
    [[ ! -e e.cells && ! -e e.node ]] || fail "a failed run wrote its output file"
    ;;

  options) # numeric options are range-checked before anything runs: exit 2, one line
    for bad in 0 -1 18446744073709551616 99999999999999999999 0x10 1.5 +3 1e3; do
      expect_error 2 "--batch: must be a whole number from 1 to" "$dynmesh" quadtree "$data/grid.txt" \
        --cells e.cells --batch "$bad"
    done
    expect_error 2 '--batch' "$dynmesh" mesh "$data/points2d.node" --postprocess quadtree -o e --batch -1
    # The largest size_t is a valid batch (one batch); leading zeros are decimal, not octal.
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells one.cells \
      --batch 18446744073709551615 --check
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells ten.cells --batch 010 --check
    for bad in -1 61 1e9 x; do
      expect_error 2 '--min-angle' "$dynmesh" mesh "$data/points2d.node" --postprocess quadtree -o e --min-angle "$bad"
    done
    expect_error 2 '--n: must be a whole number from 2 to' "$dynmesh" demo --n -5
    expect_error 2 '--n' "$dynmesh" demo --n 1
    expect_error 2 '--n' "$dynmesh" demo --n 1000000001
    expect_error 2 '--updates' "$dynmesh" demo --updates -1
    expect_error 2 '--updates' "$dynmesh" demo --updates 0x10
    expect_error 2 '--seed' "$dynmesh" demo --seed -1
    expect_error 2 '--n' "$dynmesh" stability --dim 2 --dist uniform --n -5 --csv e.csv
    expect_error 2 '--updates' "$dynmesh" stability --dim 2 --dist uniform --n 50 --updates 18446744073709551616 \
      --csv e.csv
    [[ ! -e e.cells && ! -e e.node && ! -e e.csv ]] || fail "a refused run wrote its output file"
    ;;

  dev_sh) # dev.sh with stub tools: `run` builds only bin/dynmesh, `bench` only what it runs,
    # `test` everything, `fuzz` the fuzz targets alone; apt-get waits for the dpkg lock.
    mkdir -p fake stub/build/release/bin
    cp "$data/../../../dev.sh" stub/dev.sh || fail "no dev.sh"
    log=$PWD/calls.log
    # stub PATH [BODY]: an executable that logs "NAME ARGS" to calls.log, then runs BODY.
    stub() {
      printf '#!/usr/bin/env bash\necho "%s $*" >>%q\n%s\n' "$(basename "$1")" "$log" "${2:-}" >"$1"
      chmod +x "$1"
    }
    for tool in cmake ctest apt-get; do stub "fake/$tool"; done
    stub fake/sudo '"$@"'
    # Every package installed but ninja-build.
    stub fake/dpkg-query '[[ ${*: -1} == ninja-build ]] || echo "install ok installed"'
    for prog in dynmesh sac_suite dynmesh_bench; do stub "stub/build/release/bin/$prog"; done
    dev() {
      PATH="$PWD/fake:$PATH" JOBS=1 bash stub/dev.sh "$@" >out.txt 2>err.txt || { cat err.txt >&2; fail "dev.sh $*"; }
    }
    dev run --n 10
    grep -qx 'cmake --build build/release -j 1 --target dynmesh_cli' calls.log || fail "run: $(cat calls.log)"
    [[ $(grep -c '^cmake --build' calls.log) -eq 1 ]] || fail "run builds more than bin/dynmesh: $(cat calls.log)"
    grep -qx 'dynmesh demo --n 10 --svg build/dynmesh-demo.svg' calls.log || fail "run: no demo: $(cat calls.log)"
    grep -qx 'apt-get -o DPkg::Lock::Timeout=600 update' calls.log || fail "apt-get update: $(cat calls.log)"
    grep -qx 'apt-get -o DPkg::Lock::Timeout=600 install -y --no-install-recommends ninja-build' calls.log ||
      fail "apt-get install: $(cat calls.log)"
    : >calls.log
    dev bench --csv
    grep -qx 'cmake --build build/release -j 1 --target sac_suite dynmesh_bench' calls.log ||
      fail "bench: $(cat calls.log)"
    [[ $(grep -c '^sac_suite .*--csv$' calls.log) -eq 2 && $(grep -c '^dynmesh_bench .*--csv$' calls.log) -eq 2 ]] ||
      fail "bench does not run its programs: $(cat calls.log)"
    : >calls.log
    dev test
    grep -qx 'cmake --build build/debug -j 1' calls.log || fail "test does not build everything: $(cat calls.log)"
    grep -q '^ctest --test-dir build/debug' calls.log || fail "test runs no ctest: $(cat calls.log)"
    # fuzz: a clang build of the fuzz targets alone, each run through its ctest test.
    : >calls.log
    dev fuzz 7
    grep -q '^cmake -S .* -B build/fuzz .*-DCMAKE_CXX_COMPILER=clang++ .*-DDYNMESH_FUZZ=ON -DDYNMESH_FUZZ_SECONDS=7 ' \
      calls.log || fail "fuzz: configure: $(cat calls.log)"
    grep -qx 'cmake --build build/fuzz -j 1 --target fuzz_point_readers fuzz_edit_reader fuzz_dynamic_quadtree fuzz_dynamic_mesh fuzz_hpu_mesh fuzz_octree_mesh' \
      calls.log || fail "fuzz builds more or less than the fuzz targets: $(cat calls.log)"
    grep -q "^ctest --test-dir build/fuzz -L ^fuzz\$ " calls.log || fail "fuzz runs no ctest: $(cat calls.log)"
    PATH="$PWD/fake:$PATH" bash stub/dev.sh fuzz 1.5 >out.txt 2>err.txt && fail "fuzz accepted 1.5 seconds"
    ;;

  progress) # phases of over the delay (1 s; DYNMESH_PROGRESS_DELAY_MS here) show on stderr alone
    # Delay 0: every phase ends with its line, deterministically; stdout is as without it.
    export DYNMESH_PROGRESS_DELAY_MS=0
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells p.cells --check
    cp out.txt progress_out.txt
    for line in "reading $data/points2d.node: done in " 'building the quadtree of 50 points: done in ' \
      'checking against a from-scratch build of the 43 final points: done in '; do
      grep -qF "[dynmesh] $line" err.txt || fail "quadtree: no '$line' on stderr: $(tr '\r' '|' <err.txt)"
    done
    run "$dynmesh" quadtree "$data/points3d.node" --cells p3.cells
    grep -qF '[dynmesh] building the octree of ' err.txt || fail "3D: no octree line: $(tr '\r' '|' <err.txt)"
    run "$dynmesh" mesh "$data/points2d.node" --postprocess quadtree -o p --check
    for line in 'building the quadtree mesh of 50 points: done in ' \
      'checking against a from-scratch mesh of the 50 final points: done in '; do
      grep -qF "[dynmesh] $line" err.txt || fail "mesh: no '$line' on stderr: $(tr '\r' '|' <err.txt)"
    done
    run "$dynmesh" stability --dim 2 --dist uniform --n 300 --updates 10 --csv p.csv
    grep -qF '[dynmesh] building the quadtree of 300 points: done in ' err.txt || fail "stability: no build line"
    grep -qF '[dynmesh] checking against a from-scratch build of the 300 final points: done in ' err.txt ||
      fail "stability: no check line: $(tr '\r' '|' <err.txt)"
    # A failed phase says so, and the error stays the last line.
    "$dynmesh" quadtree "$data/bad_number.txt" --cells e.cells >out.txt 2>err.txt && fail "bad_number.txt accepted"
    grep -qF "[dynmesh] reading $data/bad_number.txt: stopped after " err.txt || fail "no stopped line"
    tail -1 err.txt | grep -q '^dynmesh: .*bad_number.txt:3: ' || fail "the error is not last: $(cat err.txt)"
    # The default delay: these runs take well under a second, so stderr stays empty.
    unset DYNMESH_PROGRESS_DELAY_MS
    run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells q.cells --check
    [[ ! -s err.txt ]] || fail "a short run printed progress: $(tr '\r' '|' <err.txt)"
    cmp out.txt progress_out.txt || fail "the progress lines changed stdout"
    cmp p.cells q.cells || fail "the progress lines changed the output"
    # The live line, printed by the background thread while a build runs longer than the delay
    # (40000 points: 0.6-0.8 s in the test build, far more than 100 ms; 10000 points took about
    # 0.1 s once the quadtree got faster, and the line came or not by chance), then the final
    # line.
    # stderr is a file here, not a terminal: each report is a line of its own, without '\r'.
    # --force: the memory guard would want about 630 MiB here, and this case is about the
    # progress lines, not about how much memory the machine has free at the moment.
    DYNMESH_PROGRESS_DELAY_MS=100 run "$dynmesh" stability --dim 2 --dist uniform --n 40000 --updates 2 --force \
      --csv live.csv
    grep -qx '\[dynmesh\] building the quadtree of 40000 points: 0 s' err.txt ||
      fail "no live line during the build: $(tr '\r' '|' <err.txt)"
    grep -q '^\[dynmesh\] building the quadtree of 40000 points: done in ' err.txt || fail "no final line"
    ! grep -q $'\r' err.txt || fail "a carriage return in a log file: $(tr '\r' '|' <err.txt)"
    # At most one report per 10 s: a run of S seconds gives its first count, at most S/10
    # more, and the final one (two in the test build; a sanitizer build is slower).
    seq 1 300 | awk '{ printf "+ %.6f %.6f\n", 0.3 + $1 / 1000, 0.31 + ($1 % 7) / 1000 }' >many_edits.txt
    start=$(date +%s)
    DYNMESH_PROGRESS_DELAY_MS=0 run "$dynmesh" quadtree "$data/points2d.node" --edits many_edits.txt --cells m.cells
    reports=$(grep -c '/300 edits$' err.txt)
    ((reports >= 2 && reports <= 2 + ($(date +%s) - start) / 10)) ||
      fail "$reports edit reports in a log: $(tr '\r' '|' <err.txt)"
    grep -qx '\[dynmesh\] 300/300 edits' err.txt || fail "no final edit count: $(cat err.txt)"
    # On a terminal (script(1) gives the command one), the line is rewritten in place. A
    # container without pseudo-terminals (no /dev/pts) cannot give one: that part is skipped.
    if ! command -v script >/dev/null; then
      echo "no script(1): the terminal line is not tested"
    elif ! script -qec true /dev/null </dev/null >/dev/null 2>&1; then
      echo "script(1) cannot open a pseudo-terminal here: the terminal line is not tested"
    else
      DYNMESH_PROGRESS_DELAY_MS=0 script -qec "'$dynmesh' quadtree '$data/points2d.node' --cells t.cells 2>&1" \
        /dev/null >tty.txt </dev/null || fail "script: the run failed: $(cat tty.txt)"
      grep -q $'\r\\[dynmesh\\] building the quadtree of 50 points: done in ' tty.txt ||
        fail "no '\\r' on a terminal: $(tr '\r' '|' <tty.txt)"
    fi
    ;;

  files) # files the project did not write: Triangle's .poly and .ele, numbered rows, headers, stdin
    # A .poly file's vertices are meshed when it has no segments and no holes ...
    run "$dynmesh" mesh "$data/vertices.poly" -o poly
    run "$dynmesh" mesh "$data/vertices.node" -o node
    cmp poly.node node.node && cmp poly.ele node.ele || fail ".poly vertices: not the mesh of the same .node"
    run "$dynmesh" quadtree "$data/vertices.poly" --cells poly.cells
    # ... and refused, in one line that says why, when it has either.
    expect_error 1 'letter.poly:10: this .poly file has 6 segments: segments and holes are not supported yet' \
      "$dynmesh" mesh "$data/letter.poly" -o e
    expect_error 1 'holes are not supported yet' "$dynmesh" mesh "$data/holes_only.poly" -o e
    expect_error 1 '1 holes' "$dynmesh" quadtree "$data/holes_only.poly" --cells e.cells
    # Triangle's .ele (triangles, not points), by name and by shape; .node rows under another name.
    expect_error 1 "triangles.ele: a Triangle .ele file holds triangles" "$dynmesh" mesh "$data/triangles.ele" -o e
    expect_error 1 "triangles_ele.txt:1: this looks like Triangle's .ele format" \
      "$dynmesh" mesh "$data/triangles_ele.txt" -o e
    expect_error 1 "numbered.txt:1: this looks like Triangle's .node format" "$dynmesh" mesh "$data/numbered.txt" -o e
    cp "$data/letter.poly" letter.txt
    expect_error 1 "letter.txt:3: this looks like Triangle's .node format" "$dynmesh" quadtree letter.txt --cells e.cells
    [[ ! -e e.node && ! -e e.cells ]] || fail "a refused file gave an output"
    # A first line without a number is a header: skipped, with a note; the points are the same.
    run "$dynmesh" mesh "$data/header.csv" -o header
    grep -qx "dynmesh: note: $data/header.csv:1: skipped the header line 'easting,northing' (it holds no number)" \
      err.txt || fail "no note about the header: $(cat err.txt)"
    cmp header.node node.node || fail "a header line changed the mesh"
    # A file that fails to read gets its error alone (lines counted with the header).
    printf 'x,y\n0,0\n1,nan\n' >header_nan.csv
    expect_error 1 "header_nan.csv:3: NaN or infinite coordinate 'nan'" "$dynmesh" mesh header_nan.csv -o e
    # '-' is standard input.
    tail -n +2 "$data/header.csv" | run "$dynmesh" mesh - -o stdin
    cmp stdin.node node.node && cmp stdin.ele node.ele || fail "'-': not the mesh of the same points"
    printf '0 0\n1 x\n' | expect_error 1 "<stdin>:2: malformed number 'x'" "$dynmesh" quadtree - --cells e.cells
    # Many copies of one point: the duplicate error comes from sorting, not from comparing
    # pairs. No clock here (shared machines, sanitizer builds): a pairwise check over 3,000,000
    # copies would need about 4.5e12 comparisons, so the timeout below only catches that,
    # never a slow machine.
    yes '0.5 0.5' | head -n 80000 >copies80k.txt
    expect_error 1 'copies80k.txt:2: duplicate point' timeout 300 "$dynmesh" mesh copies80k.txt -o e
    yes '0.5 0.5' | head -n 3000000 >copies3m.txt
    expect_error 1 'copies3m.txt:2: duplicate point' timeout 300 "$dynmesh" quadtree copies3m.txt --cells e.cells --force
    rm -f copies3m.txt
    ;;

  frictions) # the small things a first user trips over
    # --version, and help that says what the command does now, pointing inside the project.
    run "$dynmesh" --version
    grep -qE '^dynmesh [0-9]+\.[0-9]+\.[0-9]+$' out.txt || fail "--version: $(cat out.txt)"
    for cmd in "" quadtree mesh stability demo; do
      # shellcheck disable=SC2086  # $cmd is zero or one word
      "$dynmesh" $cmd --help >help.txt 2>&1 || fail "dynmesh $cmd --help failed"
      ! grep -qE 'shared/|and, later' help.txt || fail "dynmesh $cmd --help: $(grep -E 'shared/|and, later' help.txt)"
    done
    "$dynmesh" mesh --help >help.txt 2>&1
    grep -q 'hpu 1 to 30' help.txt || fail "mesh --help: the --min-angle range"
    # A bad --min-angle is a malformed command line.
    expect_error 2 '--min-angle for hpu must be between 1 and 30 degrees, got 45' \
      "$dynmesh" mesh "$data/vertices.node" -o e --min-angle 45
    expect_error 2 '--min-angle' "$dynmesh" stability --dim 2 --dist uniform --n 50 --postprocess hpu \
      --min-angle 0 --csv e.csv
    # An output may not overwrite an input.
    cp "$data/final2d.txt" ok.txt
    cp ok.txt ok.orig
    expect_error 2 '--vtk ok.txt is the input file ok.txt (POINTS)' "$dynmesh" mesh ok.txt -o e --vtk ok.txt
    expect_error 2 '--vtk ./ok.txt is the input file ok.txt' "$dynmesh" mesh ok.txt -o e --vtk ./ok.txt
    cp "$data/vertices.node" v.node
    expect_error 2 '-o v.node is the input file v.node' "$dynmesh" mesh v.node -o v
    expect_error 2 '--cells ok.txt' "$dynmesh" quadtree "$data/points2d.node" --edits ok.txt --cells ok.txt
    expect_error 2 '--csv ok.txt' "$dynmesh" stability --points ok.txt --edits "$data/edits2d.txt" --csv ok.txt
    cmp ok.txt ok.orig && cmp v.node "$data/vertices.node" || fail "an input was overwritten"
    [[ ! -e e.node ]] || fail "a refused run wrote its output"
    # Binary junk: the control bytes of the message are escaped.
    printf '0 0\n1 \001\033[31m\n' >junk.txt
    expect_error 1 "junk.txt:2: malformed number '\\x01\\x1b[31m'" "$dynmesh" mesh junk.txt -o e
    ! LC_ALL=C grep -q '[[:cntrl:]]' <(tr -d '\n' <err.txt) || fail "a control byte in: $(cat -v err.txt)"
    # Two points too close for the resolution are named, not the box.
    expect_error 1 'points (0.25, 0.5) and (0.25, 0.50000000000000011) (lines 1, 2) are too close together' \
      "$dynmesh" mesh "$data/too_close.txt" -o e
    expect_error 1 '(lines 1, 2) are too close together' "$dynmesh" mesh "$data/too_close.txt" --postprocess quadtree -o e
    # An insertion outside the box suggests --box.
    expect_error 1 'edits_outside.txt:3: insert' "$dynmesh" mesh "$data/points2d.node" --edits \
      "$data/edits_outside.txt" -o e
    grep -qF 'pass --box o1 o2 L' err.txt || fail "no --box hint: $(cat err.txt)"
    expect_error 1 'pass --box o1 o2 L' "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits_outside.txt" \
      --cells e.cells
    ;;

  memory_guard) # a build that cannot fit in memory stops at once, before reading; --force goes on
    awk 'BEGIN { for (i = 1; i <= 1000; i++) printf "%d %d\n", i, (i * 7919) % 1009 }' >p.txt
    awk 'BEGIN { for (i = 1; i <= 10; i++) printf "+ %d.5 3.5\n", i }' >e.txt
    { cat p.txt; echo 'x 1'; } >bad.txt # malformed on line 1001: reading it is an error
    # Unlimited (this machine has the 43 MiB it needs), --force is accepted and changes nothing.
    run "$dynmesh" quadtree p.txt --edits e.txt --cells plain.cells
    run "$dynmesh" quadtree p.txt --edits e.txt --cells forced.cells --force
    cmp plain.cells forced.cells || fail "--force changed the tree"
    # What a ulimit leaves, and the cap, need VmSize and VmData from /proc/self/status; where
    # /proc is hidden the guard cannot know them (it then goes on uncapped): not tested there.
    proc_status=
    grep -q '^VmSize:' /proc/self/status 2>/dev/null && grep -q '^VmData:' /proc/self/status && proc_status=1
    # Under ulimit -v: 1010 points (1000 and 10 inserted) need about 32 MiB + 1010 * 10500 bytes.
    # A sanitizer build reserves terabytes of address space and cannot run under any such limit.
    limit_kib=48000
    if [[ -z $proc_status ]]; then
      echo "no VmSize and VmData in /proc/self/status: the guard under ulimit -v is not tested"
    elif (ulimit -v $limit_kib && "$dynmesh" --help) >/dev/null 2>&1; then
      limited() (ulimit -v $limit_kib && "$@")
      expect_error 1 'building the quadtree of 1010 points needs about 42.1 MiB, but only ' \
        limited "$dynmesh" quadtree p.txt --edits e.txt --cells e.cells
      grep -qF 'MiB are available (under the address-space limit, ulimit -v); pass --force to try anyway' err.txt ||
        fail "unclear message: $(cat err.txt)"
      expect_error 1 'building the quadtree mesh of 1000 points with --check needs about 133 MiB' \
        limited "$dynmesh" mesh p.txt --postprocess quadtree -o e --check
      # The hpu mesh's cost per point rises with the angle bound (memory_guard.hpp, costliest
      # inputs): 25,000 bytes at 20.7 degrees (the default), 45,000 at 30, linear in between.
      expect_error 1 'building the hpu mesh of 1010 points needs about 56.1 MiB' \
        limited "$dynmesh" mesh p.txt --edits e.txt -o e
      expect_error 1 'building the hpu mesh of 1010 points needs about 65.7 MiB' \
        limited "$dynmesh" mesh p.txt --edits e.txt -o e --min-angle 25.35
      expect_error 1 'building the hpu mesh of 1010 points needs about 75.3 MiB' \
        limited "$dynmesh" mesh p.txt --edits e.txt -o e --min-angle 30
      # The octree's tetrahedral mesh (3D points: x y z lines without --dim) has its own cost.
      awk 'BEGIN { for (i = 1; i <= 1000; i++) printf "%d %d %d\n", i, (i * 7919) % 1009, (i * 104729) % 1013 }' >p3.txt
      expect_error 1 'building the octree mesh of 1000 points needs about ' limited "$dynmesh" mesh p3.txt -o e
      # stability --points counts as they do: the 1000 points and the 10 '+' lines (and its check).
      expect_error 1 'building the quadtree of 1010 points needs about 46.4 MiB' \
        limited "$dynmesh" stability --points p.txt --edits e.txt --csv e.csv
      # Before reading: the malformed line is not reached.
      expect_error 1 'building the quadtree of 1001 points needs about' limited "$dynmesh" quadtree bad.txt \
        --cells e.cells
      # --force skips the guard: reading reports the malformed line, a good file reaches the build.
      expect_error 1 'bad.txt:1001: ' limited "$dynmesh" quadtree bad.txt --cells e.cells --force
      DYNMESH_PROGRESS_DELAY_MS=0 limited "$dynmesh" quadtree p.txt --edits e.txt --cells forced.cells --force \
        >out.txt 2>err.txt
      grep -qF '[dynmesh] building the quadtree of 1000 points: ' err.txt ||
        fail "--force did not reach the build: $(tr '\r' '|' <err.txt)"
      ! grep -q 'pass --force' err.txt || fail "--force did not skip the guard: $(cat err.txt)"
      [[ ! -e e.cells && ! -e e.node ]] || fail "a refused run wrote its output file"
      # The estimate is per point, and points along a line cost more than any constant
      # foresees (3D: about twice it). The guard lets 20,000 of them go on under 600 MB and
      # caps the build there; it outgrows the cap and stops with the guard's figures, not a
      # bare std::bad_alloc (nor, without a ulimit, the OOM killer), and writes nothing.
      awk 'BEGIN { for (i = 1; i <= 20000; i++) { t = (i * i % 100003) / 100003
                   printf "%.17g %.17g %.17g\n", t, 0.5 * t + 0.1, 0.25 * t + 0.2 } }' >line3.txt
      quiet() { env DYNMESH_PROGRESS_DELAY_MS=100000000 "$@"; }
      limited600() (ulimit -v 600000 && "$@")
      # The machine must have those 600 MB free: with less, the guard refuses the build up
      # front (rightly: MemAvailable is the smaller bound), which is not what this checks.
      mem_kib=$(awk '/^MemAvailable:/ { print $2 }' /proc/meminfo 2>/dev/null)
      if [[ -n $mem_kib ]] && ((mem_kib < 600000)); then
        echo "MemAvailable is $mem_kib kB, under the 600000 KiB limit: a build outgrowing its cap is not tested"
      else
        expect_error 1 'out of memory: building the octree of 20000 points was estimated at about 423 MiB and allowed' \
          limited600 quiet "$dynmesh" quadtree line3.txt --dim 3 --cells e.cells
        grep -qF 'points along a line or a curve can need up to twice it; pass --force' err.txt ||
          fail "no hint: $(cat err.txt)"
        expect_error 1 'out of memory (std::bad_alloc); the run stopped before writing its outputs' \
          limited600 quiet "$dynmesh" quadtree line3.txt --dim 3 --cells e.cells --force
        [[ ! -e e.cells ]] || fail "a build out of memory wrote its output file"
      fi
    else
      echo "the program cannot run under ulimit -v $limit_kib (a sanitizer build?): the limit is not tested"
    fi
    # The cap itself: while a guarded build waits for its points on a FIFO (the guard counts a
    # pipe as empty), its data-size limit is finite (VmData plus MemAvailable); with --force
    # it stays unlimited. Then the points come and the build ends as usual. The limit is read
    # from /proc/PID/limits (not there under a restricted /proc: not tested then); the wait
    # for it is long (a loaded machine, a sanitizer build) but ends as soon as it is seen.
    if [[ $(ulimit -d) == unlimited && -n $proc_status && -r /proc/self/limits ]]; then
      mkfifo pts.fifo
      for force in "" --force; do
        "$dynmesh" quadtree pts.fifo --cells f.cells $force >out.txt 2>err.txt &
        pid=$!
        data_limit=unlimited
        for _ in $(seq 600); do
          sleep 0.1
          data_limit=$(awk '/^Max data size/ { print $4 }' "/proc/$pid/limits")
          [[ $data_limit != unlimited || -n $force ]] && break
        done
        printf '1 2\n3 5\n8 13\n' >pts.fifo
        wait "$pid" || fail "the build on the FIFO failed: $(cat err.txt)"
        if [[ -z $force ]]; then
          [[ $data_limit =~ ^[0-9]+$ ]] || fail "a guarded build's data size is not capped: $data_limit"
        else
          [[ $data_limit == unlimited ]] || fail "--force capped the data size: $data_limit"
        fi
      done
    else
      echo "ulimit -d is set, or /proc/self/status or /proc/PID/limits cannot be read: the cap is not tested"
    fi
    # MemAvailable: no machine has the 14 TiB of 10^9 points; refused before generating any.
    expect_error 1 'building the quadtree of 1000000000 points needs about 13.6 TiB, but only ' \
      "$dynmesh" stability --dim 2 --dist uniform --n 1000000000 --updates 0 --csv e.csv
    expect_error 1 'building the octree of 1000000001 points needs about ' \
      "$dynmesh" stability --dim 3 --dist uniform --n 1000000000 --updates 2 --csv e.csv
    [[ ! -e e.csv ]] || fail "a refused stability run wrote its CSV"
    ;;

  svg_options) # --svg-point-radius and --svg-max-points; dots shrink with density by default
    # radius_of SVG: the distinct r="..." values of the dots.
    radius_of() { grep -o '<circle [^>]* r="[^"]*"' "$1" | sed 's/.* r="//; s/"$//' | sort -u | tr '\n' ' '; }
    final=$(grep -vc '^#' "$data/final2d.txt") # 43 points after the edits
    qt() { run "$dynmesh" quadtree "$data/points2d.node" --edits "$data/edits2d.txt" --cells s.cells "$@"; }
    qt --svg default.svg
    [[ $(radius_of default.svg) == '1 ' ]] || fail "few points: radius $(radius_of default.svg), expected 1"
    qt --svg big.svg --svg-point-radius 2.5
    [[ $(radius_of big.svg) == '2.5 ' ]] || fail "--svg-point-radius 2.5: radius $(radius_of big.svg)"
    [[ $(grep -c '<circle' big.svg) -eq $final ]] || fail "--svg-point-radius changed the dots"
    qt --svg at.svg --svg-max-points "$final"
    [[ $(grep -c '<circle' at.svg) -eq $final ]] || fail "--svg-max-points $final: not every point drawn"
    qt --svg over.svg --svg-max-points $((final - 1))
    [[ $(grep -c '<circle' over.svg) -eq 0 ]] || fail "--svg-max-points $((final - 1)): points drawn"
    grep -qF "$final points (not drawn: more than $((final - 1)))" over.svg || fail "the title does not say so"
    cmp <(sed '/<title>/d; /<g fill="#c0392b">/,/<\/g>/d' default.svg) <(grep -v '<title>' over.svg) ||
      fail "leaving the points out changed the rest of the picture"
    # Density: 128^2 = 16384 points (under the default 20000) get 0.1 * 1000 / 128 = 0.78 px
    # dots; one point fewer allowed than given, none.
    awk 'BEGIN { for (i = 0; i < 128; i++) for (j = 0; j < 128; j++) printf "%d %d\n", i, j }' >grid.txt
    run "$dynmesh" quadtree grid.txt --cells grid.cells --svg grid.svg
    [[ $(grep -c '<circle' grid.svg) -eq 16384 && $(radius_of grid.svg) == '0.78 ' ]] ||
      fail "16384 points: $(grep -c '<circle' grid.svg) dots of radius $(radius_of grid.svg)"
    # The mesh: the same options (its own default radius, 1.5 px, on few points).
    mesh() { run "$dynmesh" mesh "$data/points2d.node" --postprocess quadtree -o m "$@"; }
    mesh --svg m.svg
    [[ $(radius_of m.svg) == '1.5 ' ]] || fail "mesh: radius $(radius_of m.svg), expected 1.5"
    mesh --svg m2.svg --svg-point-radius 0.6
    [[ $(radius_of m2.svg) == '0.6 ' ]] || fail "mesh --svg-point-radius 0.6: radius $(radius_of m2.svg)"
    mesh --svg m0.svg --svg-max-points 0
    [[ $(grep -c '<circle' m0.svg) -eq 0 && $(grep -c '<circle' m.svg) -gt 0 ]] || fail "mesh --svg-max-points 0"
    # The options need --svg and a sensible value.
    expect_error 2 '--svg' "$dynmesh" quadtree "$data/points2d.node" --cells e.cells --svg-point-radius 2
    expect_error 2 '--svg-point-radius' "$dynmesh" quadtree "$data/points2d.node" --cells e.cells --svg e.svg \
      --svg-point-radius 0
    expect_error 2 '--svg-max-points' "$dynmesh" mesh "$data/points2d.node" --postprocess quadtree -o e \
      --svg e.svg --svg-max-points -1
    [[ ! -e e.cells && ! -e e.svg ]] || fail "a refused run wrote its output file"
    ;;

  dimensions) # the dimension of a point file (docs/FORMATS.md, "Input points"), in every command
    # that reads one: --dim, a .node header, or the count of numbers on the first line
    awk '/^#/ { next } { print $1, $2 }' "$data/final3d.txt" >xy.txt # final3d.txt's first two columns
    # x y z lines without --dim are 3D, never their (x, y) projection.
    run "$dynmesh" quadtree "$data/final3d.txt" --cells a.cells
    grep -qx '# dim 3' a.cells || fail "final3d.txt without --dim: not 3D"
    run "$dynmesh" mesh "$data/final3d.txt" -o m3
    [[ $(head -1 m3.node | cut -d' ' -f2-) == '3 0 1' ]] || fail "mesh final3d.txt: $(head -1 m3.node)"
    # With --dim 2 the first two numbers are the coordinates and the third is ignored.
    run "$dynmesh" quadtree "$data/final3d.txt" --dim 2 --cells q2.cells
    run "$dynmesh" quadtree xy.txt --cells qxy.cells
    cmp q2.cells qxy.cells || fail "--dim 2 on x y z lines is not the tree of their (x, y)"
    run "$dynmesh" mesh "$data/final3d.txt" --dim 2 --postprocess quadtree -o m2
    run "$dynmesh" mesh xy.txt --postprocess quadtree -o mxy
    cmp m2.node mxy.node && cmp m2.ele mxy.ele || fail "mesh --dim 2 on x y z lines is not the mesh of their (x, y)"
    # More numbers than 3 on the first line (normals after the coordinates): --dim says which.
    for cmd in "quadtree --cells e.cells" "mesh -o e"; do
      # shellcheck disable=SC2086  # $cmd is several words
      expect_error 1 'scan.xyz:1: the first line of numbers holds 6 numbers' "$dynmesh" $cmd "$data/scan.xyz"
      grep -qF -- 'pass --dim 2 or --dim 3' err.txt || fail "no --dim hint: $(cat err.txt)"
    done
    printf '+ 1 1 1\n' >e3.txt
    expect_error 1 'scan.xyz:1: the first line of numbers holds 6' "$dynmesh" stability --points "$data/scan.xyz" \
      --edits e3.txt --csv e.csv
    run "$dynmesh" mesh "$data/scan.xyz" --dim 3 -o s3 --check
    [[ $(head -1 s3.node | cut -d' ' -f2-) == '3 0 1' ]] || fail "scan.xyz --dim 3: $(head -1 s3.node)"
    # Every later line holds as many numbers as the first: an error naming the line otherwise.
    printf '0.1 0.2 0.3\n0.4 0.5 0.6\n0.7 0.8\n0.9 0.1 0.2\n' >mixed.txt
    expect_error 1 'mixed.txt:3: expected 3 numbers as on line 1' "$dynmesh" quadtree mixed.txt --cells e.cells
    expect_error 1 'mixed.txt:3: expected 3 numbers as on line 1' "$dynmesh" mesh mixed.txt -o e
    expect_error 1 'mixed.txt:3: expected 3 numbers' "$dynmesh" stability --points mixed.txt --edits e3.txt --csv e.csv
    printf '# two, then three\n0.1 0.2\n0.4 0.5 0.6\n' >mixed2.txt
    expect_error 1 'mixed2.txt:3: expected 2 numbers as on line 2' "$dynmesh" mesh mixed2.txt -o e
    # With --dim, only the count below it is an error: --dim 2 reads mixed.txt, --dim 3 refuses line 3.
    run "$dynmesh" quadtree mixed.txt --dim 2 --cells mixed.cells
    expect_error 1 'mixed.txt:3: expected 3 coordinates, found 2' "$dynmesh" quadtree mixed.txt --dim 3 --cells e.cells
    # A 2D file given --dim 3, and a .node header that disagrees with --dim, either way.
    first=$(grep -n -m1 -v '^#' "$data/final2d.txt" | cut -d: -f1)
    expect_error 1 "final2d.txt:$first: expected 3 coordinates, found 2" "$dynmesh" mesh "$data/final2d.txt" --dim 3 -o e
    expect_error 1 'points3d.node:1: ' "$dynmesh" mesh "$data/points3d.node" --dim 2 -o e
    expect_error 1 'points2d.node:2: ' "$dynmesh" mesh "$data/points2d.node" --dim 3 -o e
    expect_error 1 'points2d.node:2: ' "$dynmesh" quadtree "$data/points2d.node" --dim 3 --cells e.cells
    # A column header, ',' separators and standard input: the count is of the numbers.
    { echo 'x,y,z'; awk '/^#/ { next } { print $1 "," $2 "," $3 }' "$data/final3d.txt"; } >h.csv
    run "$dynmesh" quadtree h.csv --cells h.cells
    cmp a.cells h.cells || fail "a header and commas changed the tree"
    grep -v '^#' "$data/final3d.txt" | run "$dynmesh" quadtree - --cells stdin.cells
    cmp a.cells stdin.cells || fail "'-': not the 3D tree of the same points"
    grep -v '^#' "$data/final3d.txt" | run "$dynmesh" mesh - -o stdin
    cmp m3.node stdin.node && cmp m3.ele stdin.ele || fail "'-': not the 3D mesh of the same points"
    # A pipe (not a regular file) is read once: looking at its first line loses nothing.
    run "$dynmesh" quadtree <(grep -v '^#' "$data/final3d.txt") --cells pipe.cells
    cmp a.cells pipe.cells || fail "a pipe: not the 3D tree of the same points"
    # Edit scripts give as many coordinates as the points have.
    printf '+ 0.5 0.5\n' >e2.txt
    expect_error 1 'e2.txt:1: an edit needs exactly 3 coordinates (the points are 3D), found 2' \
      "$dynmesh" quadtree "$data/final3d.txt" --edits e2.txt --cells e.cells
    expect_error 1 'e2.txt:1: an edit needs exactly 3 coordinates' "$dynmesh" mesh "$data/final3d.txt" --edits e2.txt -o e
    expect_error 1 'e3.txt:1: an edit needs exactly 2 coordinates (the points are 2D), found 3' \
      "$dynmesh" mesh xy.txt --edits e3.txt -o e
    [[ ! -e e.cells && ! -e e.node && ! -e e.csv ]] || fail "a failed run wrote its output file"
    ;;

  mesh3d) # `dynmesh mesh` in 3D: the octree's tetrahedral mesh (docs/FORMATS.md, "dynmesh mesh in 3D")
    edits=$(grep -c '^[+-]' "$data/edits3d.txt")
    # tets_of NODE ELE: one sorted line per tetrahedron, its corners as the .node writes them
    # (%.17g), in the .ele's order: the form of the feed's lines.
    tets_of() {
      awk 'NR == FNR { if (FNR > 1) xyz[$1] = $2 " " $3 " " $4; next }
        FNR > 1 { print xyz[$2], xyz[$3], xyz[$4], xyz[$5] }' "$1" "$2" | LC_ALL=C sort
    }
    # replay TETS FEED: TETS with every update's '-' lines removed and '+' lines added, in order;
    # fails when a removed tetrahedron is absent or an added one is present.
    replay() {
      awk 'NR == FNR { have[$0] = 1; next }
        /^[-+] / { t = substr($0, 3); if ($1 == "-") { bad = bad || !(t in have); delete have[t] }
                   else { bad = bad || (t in have); have[t] = 1 } }
        END { for (t in have) print t; exit bad }' "$1" "$2" | LC_ALL=C sort
    }
    run "$dynmesh" quadtree "$data/points3d.node" --cells box.cells
    box=$(box_of box.cells) # the box derived from points3d.node, as the mesh derives it
    # A 3D .node header decides the dimension; every output, --check and --stats.
    run "$dynmesh" mesh "$data/points3d.node" --edits "$data/edits3d.txt" -o dyn --check --feed dyn.feed \
      --vtk dyn.vtk --msh dyn.msh --stats
    cp err.txt stats.txt
    [[ $(head -1 dyn.node | cut -d' ' -f2-) == '3 0 1' ]] || fail "dyn.node header: $(head -1 dyn.node)"
    [[ $(head -1 dyn.ele | cut -d' ' -f2-) == '4 0' ]] || fail "dyn.ele header: $(head -1 dyn.ele)"
    [[ $(head -1 dyn.node | cut -d' ' -f1) -eq $(($(wc -l <dyn.node) - 1)) ]] || fail "dyn.node: vertex count"
    [[ $(head -1 dyn.ele | cut -d' ' -f1) -eq $(($(wc -l <dyn.ele) - 1)) ]] || fail "dyn.ele: tetrahedron count"
    awk 'NR > 1 && (NF != 5 || $1 != NR - 1 || ($5 != 0 && $5 != 1)) { bad = 1; print } END { exit bad }' dyn.node ||
      fail "dyn.node lines"
    # Canonical: numbered from 1, the smallest vertex first, then the smallest of the other three;
    # tetrahedra sorted.
    awk 'NR > 1 && (NF != 5 || $1 != NR - 1 || !($2 < $3 && $2 < $4 && $2 < $5 && $3 < $4 && $3 < $5)) { bad = 1; print }
      END { exit bad }' dyn.ele || fail "dyn.ele lines are not canonical"
    tail -n +2 dyn.ele | cut -d' ' -f2- | sort -c -n -k1,1 -k2,2 -k3,3 -k4,4 || fail "dyn.ele is not sorted"
    # The same files with --dim 3, and from scratch on the final points in the same box.
    run "$dynmesh" mesh "$data/points3d.node" --dim 3 --edits "$data/edits3d.txt" -o again
    cmp dyn.node again.node && cmp dyn.ele again.ele || fail "two runs differ"
    # shellcheck disable=SC2086  # the box is several numbers
    run "$dynmesh" mesh "$data/final3d.txt" --box $box -o scratch --check --postprocess quadtree
    cmp dyn.node scratch.node || fail "dynamic .node differs from a from-scratch run on final3d.txt"
    cmp dyn.ele scratch.ele || fail "dynamic .ele differs from a from-scratch run on final3d.txt"
    run "$dynmesh" mesh "$data/points3d.node" --edits "$data/edits3d.txt" --batch 3 -o batch3 --feed batch3.feed --check
    cmp dyn.node batch3.node && cmp dyn.ele batch3.ele || fail "--batch 3 differs from single edits"
    [[ $(grep -c '^update ' batch3.feed) -eq $(((edits + 2) / 3)) ]] || fail "--batch 3: wrong number of updates"
    # The feed: one update per edit, 12 numbers a line, and replayed on the initial mesh it gives
    # the final one.
    [[ $(head -1 dyn.feed) == '# dynmesh feed v1' ]] || fail "feed header: $(head -1 dyn.feed)"
    [[ $(grep -c '^update ' dyn.feed) -eq $edits ]] || fail "feed: expected $edits updates"
    [[ $(grep -m1 '^update ' dyn.feed | cut -d' ' -f2) == 1 ]] || fail "feed: first update is not 1"
    awk '/^[-+] / && NF != 13 { bad = 1; print } END { exit bad }' dyn.feed || fail "feed lines of other than 12 numbers"
    run "$dynmesh" mesh "$data/points3d.node" -o start
    tets_of start.node start.ele >start.tets
    tets_of dyn.node dyn.ele >final.tets
    replay start.tets dyn.feed >replayed.tets || fail "the feed removes an absent tetrahedron or adds a present one"
    cmp replayed.tets final.tets || fail "the feed replayed on the initial mesh does not give the final .ele"
    replay start.tets batch3.feed >replayed3.tets && cmp replayed3.tets final.tets || fail "--batch 3 feed replay"
    # --stats: the tetrahedral report, then the propagations as in 2D.
    for want in 'Smallest dihedral' 'Largest dihedral' 'radius-edge ratio' 'Tetrahedra per input point' \
      'Propagation statistics:' "  Propagations: $edits    Edits: $edits"; do
      grep -qF "$want" stats.txt || fail "--stats lacks '$want': $(cat stats.txt)"
    done
    want=$(awk '/^update / { t += $4 + $6; k++ } END { printf "%g", t / k }' dyn.feed)
    grep -qx "  Mean tetrahedra changed: $want (removed + added)" stats.txt || fail "not the feed's mean $want"
    grep -qE '^  Maximum time: +[0-9.e+-]+ s +\|  Mean trace distance: [1-9][0-9.e+]*$' stats.txt ||
      fail "--stats: maximum time, trace distance"
    # VTK cell type 10, Gmsh element type 4.
    head -1 dyn.vtk | grep -q '^# vtk DataFile' || fail "dyn.vtk is not legacy VTK"
    awk '/^CELL_TYPES/ { n = $2; on = 1; next } on && n-- > 0 && $1 != 10 { bad = 1 } END { exit bad || !on }' dyn.vtk ||
      fail "dyn.vtk: cell types other than 10"
    awk '/^\$Elements/ { on = 1; getline; next } /^\$EndElements/ { on = 0 } on && $2 != 4 { bad = 1 }
      END { exit bad }' dyn.msh || fail "dyn.msh: elements other than type 4"
    # Plain x y z lines without --dim mesh in 3D.
    run "$dynmesh" mesh "$data/final3d.txt" -o plain --check
    [[ $(head -1 plain.ele | cut -d' ' -f2-) == '4 0' ]] || fail "final3d.txt: not tetrahedra"
    # The 2D mesh's options are malformed command lines in 3D (exit 2), with --dim 3 or without.
    for dim in "" "--dim 3"; do
      # shellcheck disable=SC2086  # $dim is zero or two words
      expect_error 2 '--postprocess hpu is 2D only; the 3D mesh is the octree'"'"'s (--postprocess quadtree)' \
        "$dynmesh" mesh "$data/final3d.txt" $dim --postprocess hpu -o e
      # shellcheck disable=SC2086
      expect_error 2 '--min-angle is 2D only' "$dynmesh" mesh "$data/final3d.txt" $dim --min-angle 10 -o e
      # shellcheck disable=SC2086
      expect_error 2 '--min-angle is 2D only' "$dynmesh" mesh "$data/final3d.txt" $dim --postprocess quadtree \
        --min-angle 10 -o e
      # shellcheck disable=SC2086
      expect_error 2 '--svg draws 2D meshes only' "$dynmesh" mesh "$data/final3d.txt" $dim --svg e.svg -o e
    done
    expect_error 2 '--postprocess hpu is 2D only' "$dynmesh" mesh "$data/points3d.node" --postprocess hpu -o e
    [[ ! -e e.node && ! -e e.svg ]] || fail "a refused run wrote its output"
    # Bad edit lines (a wrong count, an absent point, a point outside the box): one line naming
    # the line, exit 1, and the files of the earlier run as they were.
    for f in node ele feed; do cp "dyn.$f" "saved.$f"; done
    { head -3 "$data/edits3d.txt"; echo '+ 1.5 2.5'; } >count3.txt
    { head -3 "$data/edits3d.txt"; echo '- 1.5 2.5 3.5'; } >absent3.txt
    { head -3 "$data/edits3d.txt"; echo '+ 100 0 0'; } >outside3.txt
    expect_error 1 'count3.txt:4: an edit needs exactly 3 coordinates' "$dynmesh" mesh "$data/points3d.node" \
      --edits count3.txt -o dyn --feed dyn.feed
    for batch in "" "--batch 2"; do
      # shellcheck disable=SC2086  # $batch is zero or two words
      expect_error 1 'absent3.txt:4: ' "$dynmesh" mesh "$data/points3d.node" --edits absent3.txt $batch -o dyn \
        --feed dyn.feed
      grep -q 'not in the set' err.txt || fail "absent point: unclear message: $(cat err.txt)"
      # shellcheck disable=SC2086
      expect_error 1 'outside3.txt:4: insert' "$dynmesh" mesh "$data/points3d.node" --edits outside3.txt $batch \
        -o dyn --feed dyn.feed
      grep -qF 'pass --box o1 o2 o3 L' err.txt || fail "no --box hint: $(cat err.txt)"
    done
    for f in node ele feed; do cmp "dyn.$f" "saved.$f" || fail "a failed run changed dyn.$f"; done
    [[ -z $(find . -name '.*.tmp-*') ]] || fail "temporary files left behind: $(find . -name '.*.tmp-*')"
    # stability --postprocess quadtree in 3D: the same updates as the octree alone, each costing
    # more (the whole update, tree and mesh), the final mesh verified.
    run "$dynmesh" stability --dim 3 --dist clusters --n 300 --updates 20 --seed 3 --csv tree.csv
    run "$dynmesh" stability --dim 3 --dist clusters --n 300 --updates 20 --seed 3 --postprocess quadtree \
      --csv mesh.csv
    grep -q '^stability: octree mesh, clusters 3D' out.txt || fail "the 3D mesh run: $(cat out.txt)"
    [[ $(wc -l <mesh.csv) -eq 21 ]] || fail "3D mesh CSV: expected header + 20 rows"
    paste -d, <(tail -n +2 tree.csv) <(tail -n +2 mesh.csv) | awk -F, '$2 != 3 || $4 != $11 || $5 != $12 ||
      $13 <= $6 { bad = 1; print } END { exit bad }' || fail "3D mesh rows do not follow the octree rows"
    run "$dynmesh" stability --points "$data/points3d.node" --edits "$data/edits3d.txt" --csv ptree.csv
    run "$dynmesh" stability --points "$data/points3d.node" --edits "$data/edits3d.txt" --postprocess quadtree \
      --csv pmesh.csv
    [[ $(wc -l <pmesh.csv) -eq $((edits + 1)) ]] || fail "3D --points: expected header + $edits rows"
    paste -d, <(tail -n +2 ptree.csv) <(tail -n +2 pmesh.csv) | awk -F, '$1 != "points3d" || $2 != 3 || $4 != $11 ||
      $5 != $12 || $13 <= $6 { bad = 1; print } END { exit bad }' || fail "3D --points mesh rows"
    ;;

  *)
    fail "unknown case"
    ;;
esac
echo "ok [$case_name]"
