#!/usr/bin/env bash
# tests/mpi/mpi_test.sh CASE MPIEXEC DYNMESH DYNMESH_MPI MPI_GEN WORK_DIR — end-to-end tests of
# `dynmesh-mpi quadtree` (docs/FORMATS.md, docs/DISTRIBUTED.md): its `.cells` must equal
# `dynmesh quadtree`'s byte for byte for every number of ranks; bad input gives one line from
# rank 0 and a non-zero status on every rank, within a timeout. One ctest per CASE
# (tests/mpi/CMakeLists.txt). Exit 0 pass, 1 fail.
set -uo pipefail

case_name=$1 mpiexec=$2 dynmesh=$3 dmpi=$4 gen=$5 work=$6
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
export DYNMESH_PROGRESS_DELAY_MS=3600000

fail() {
  echo "FAIL [$case_name]: $*" >&2
  exit 1
}

# mpi P ARGS...: dynmesh-mpi on P ranks (more ranks than cores: --oversubscribe; -q: no
# launcher chatter on stderr), killed after 120 s so that a hang fails instead of blocking.
mpi() {
  local p=$1
  shift
  timeout 120 "$mpiexec" -q --oversubscribe -np "$p" "$dmpi" "$@"
}

# same P POINTS ARGS...: dynmesh-mpi on P ranks writes the .cells that dynmesh wrote to ref.cells.
same() {
  local p=$1
  shift
  mpi "$p" quadtree "$@" --cells mpi.cells >out.txt 2>err.txt || { cat err.txt >&2; fail "exit status $?: -np $p $*"; }
  cmp -s ref.cells mpi.cells || fail "-np $p $*: .cells differs from dynmesh quadtree's"
}

# exact DIM DIST N SPREAD NEDITS [ARGS...]: generated input and edits; 1 to 4 ranks, single
# edits and batches, against dynmesh quadtree.
exact() {
  local dim=$1 dist=$2 n=$3 spread=$4 nedits=$5
  shift 5
  "$gen" "$dist" "$dim" "$n" 7 "$spread" in.xyz in.edits "$nedits" || fail "mpi_gen $dist"
  "$dynmesh" quadtree in.xyz --dim "$dim" --edits in.edits --cells ref.cells "$@" || fail "dynmesh quadtree $dist"
  for p in 1 2 3 4; do
    same "$p" in.xyz --dim "$dim" --edits in.edits --batch 9 "$@"
  done
  same 3 in.xyz --dim "$dim" --edits in.edits "$@"
}

# expect_error WANT_TEXT ARGS...: on 3 ranks, every rank exits non-zero, stderr is exactly one
# line "dynmesh-mpi: ..." containing WANT_TEXT (and dynmesh's own message), no .cells.
expect_error() {
  local want=$1
  shift
  rm -f status.txt err.cells
  timeout 120 "$mpiexec" -q --oversubscribe -np 3 sh -c '"$0" "$@"; echo "$?" >>status.txt' "$dmpi" quadtree "$@" \
    --cells err.cells >out.txt 2>err.txt
  local rc=$?
  ((rc != 124)) || fail "timed out (a rank hangs): $*"
  [[ $(wc -l <status.txt) -eq 3 ]] || fail "not every rank finished: $*"
  grep -qx 0 status.txt && fail "a rank exited 0: $*"
  [[ $(wc -l <err.txt) -eq 1 ]] || { cat err.txt >&2; fail "stderr is not exactly one line: $*"; }
  grep -q '^dynmesh-mpi: ' err.txt || fail "stderr does not start with 'dynmesh-mpi: ': $(cat err.txt)"
  grep -qF -- "$want" err.txt || fail "stderr lacks '$want': $(cat err.txt)"
  [[ ! -e err.cells ]] || fail "a failed run wrote its output: $*"
  # The message is dynmesh quadtree's.
  "$dynmesh" quadtree "$@" --cells err1.cells >/dev/null 2>err1.txt && fail "dynmesh quadtree accepted $*"
  [[ "$(sed 's/^dynmesh-mpi: //' err.txt)" == "$(sed 's/^dynmesh: //' err1.txt)" ]] ||
    fail "message differs from dynmesh quadtree's: $(cat err.txt) / $(cat err1.txt)"
}

case $case_name in
  exact2d) # 2D: uniform, clusters, shrinking (spread 2^30), spiral, boundary
    exact 2 uniform 1500 2 300
    exact 2 clusters 1500 2 300
    exact 2 shrinking 1500 1073741824 300
    exact 2 spiral 1500 2 300
    exact 2 boundary 1000 2 200
    ;;
  exact3d) # the same in 3D
    exact 3 uniform 800 2 150
    exact 3 clusters 800 2 150
    exact 3 shrinking 800 1073741824 150
    exact 3 spiral 800 2 150
    exact 3 boundary 600 2 150
    ;;
  root_boundaries) # points exactly on the root cells' boundaries, at several partition levels
    # A dyadic box and a lattice of step 1/16: every point lies on a boundary of every level
    # up to 4, and each sees its lattice neighbours.
    for dim in 2 3; do
      if ((dim == 2)); then
        awk 'BEGIN { for (i = 4; i < 12; i++) for (j = 4; j < 12; j++) if ((i * 7 + j * 3) % 5) print i / 16, j / 16 }' >g.xyz
        awk 'BEGIN { for (i = 4; i < 10; i += 2) print "- " i / 16, 5 / 16; print "+ 0.5 0.5078125"; print "+ 0.3125 0.3125" }' >g.edits
        box=(0 0 1)
      else
        awk 'BEGIN { for (i = 5; i < 11; i++) for (j = 5; j < 11; j++) for (k = 5; k < 11; k++) if ((i + 2 * j + 3 * k) % 4) print i / 16, j / 16, k / 16 }' >g.xyz
        awk 'BEGIN { print "- 0.3125 0.3125 0.3125"; print "+ 0.5 0.5 0.5078125" }' >g.edits
        box=(0 0 0 1)
      fi
      grep -q . g.xyz || fail "no lattice"
      "$dynmesh" quadtree g.xyz --dim "$dim" --box "${box[@]}" --edits g.edits --cells ref.cells || fail "dynmesh on the lattice"
      for level in 0 1 2 3 4 5; do
        for p in 2 3; do same "$p" g.xyz --dim "$dim" --box "${box[@]}" --edits g.edits --partition-level "$level"; done
      done
    done
    ;;
  ghost_ring) # the ring width of docs/DISTRIBUTED.md: one ring narrower breaks exactness here
    "$gen" uniform 2 2000 1 2 u.xyz u.edits 200 || fail "mpi_gen"
    "$dynmesh" quadtree u.xyz --edits u.edits --cells ref.cells || fail "dynmesh"
    same 3 u.xyz --edits u.edits --ghost-ring 1
    mpi 3 quadtree u.xyz --edits u.edits --ghost-ring 0 --cells narrow.cells 2>err.txt || fail "ring 0 failed to run"
    cmp -s ref.cells narrow.cells && fail "a ghost ring of width 0 gave the exact tree: the test input no longer shows the need"
    ;;
  repartition) # edits that empty the lower half and fill the upper one move root cells; still exact
    "$gen" uniform 2 1200 5 2 u.xyz unused.edits 0 || fail "mpi_gen"
    # Every point below y = 0.5 moves to the upper half (y/2 + 0.5), deleted then inserted:
    # the Morton order halves y first, so the lower ranks lose their points.
    awk '$2 < 0.5 { printf "- %.17g %.17g\n+ %.17g %.17g\n", $1, $2, $1, $2 / 2 + 0.5 }' u.xyz >move.edits
    "$dynmesh" quadtree u.xyz --box 0 0 1 --edits move.edits --cells ref.cells || fail "dynmesh"
    for p in 2 3 4; do
      same "$p" u.xyz --box 0 0 1 --edits move.edits --batch 50 --stats
      grep -q ' [1-9][0-9]* repartitions' err.txt || { cat err.txt >&2; fail "-np $p: no repartition happened"; }
    done
    same 2 u.xyz --box 0 0 1 --edits move.edits --batch 50 --rebalance 0
    ;;
  errors) # malformed, NaN, duplicate, outside the box, absent deletion, spread beyond the resolution
    "$gen" uniform 2 300 3 2 s.xyz s.edits 20 || fail "mpi_gen"
    printf '0.5 0.5\n0.5 abc\n' >bad.xyz
    printf '0.5 0.5\nnan 0.2\n' >nan.xyz
    printf '0.5 0.5\n0.1 0.2\n0.5 0.5\n' >dup.xyz
    printf '0.5 0.5\n0.1 0.2\n0.5 0.50000000000000011\n' >res.xyz
    echo "- 0.123 0.456" >absent.edits
    echo "+ 5 5" >outside.edits
    echo "+ 0.2 inf" >inf.edits
    { head -4 s.edits; echo "- 0.123 0.456"; } >late.edits
    x=$(sed -n 10p s.xyz | awk '{ printf "%.17g %.17g", $1, $2 + 1e-16 }')
    echo "+ $x" >res.edits
    expect_error "malformed number" bad.xyz
    expect_error "NaN or infinite" nan.xyz
    expect_error "duplicate point" dup.xyz
    expect_error "resolution" res.xyz
    expect_error "not in the set" s.xyz --edits absent.edits
    expect_error "late.edits:5:" s.xyz --edits late.edits --batch 3
    expect_error "outside the domain box" s.xyz --edits outside.edits
    expect_error "NaN or infinite" s.xyz --edits inf.edits
    expect_error "exceeds the resolution" s.xyz --edits res.edits --batch 2
    expect_error "cannot open" missing.xyz
    ;;
  real_world) # data the project did not write: gnuplot's world coastline (gnuplot-doc, dev.sh deps)
    world=/usr/share/doc/gnuplot/examples/world.dat
    [[ -r $world ]] || fail "$world is missing (bash dev.sh deps installs gnuplot-doc)"
    # Its "lon lat" rows, without comments and the blank lines between coastlines; the
    # coastlines repeat some points, hence --duplicates skip.
    grep -v '^#' "$world" | awk 'NF >= 2 { print $1, $2 }' >w.xyz
    (($(wc -l <w.xyz) > 1000)) || fail "world.dat: too few points"
    # Delete every 7th distinct point, then insert every other of those back.
    awk '!seen[$0]++' w.xyz | awk 'NR % 7 == 1 { print "- " $0 } NR % 14 == 1 { keep[++k] = $0 }
      END { for (i = 1; i <= k; i++) print "+ " keep[i] }' >w.edits
    "$dynmesh" quadtree w.xyz --duplicates skip --edits w.edits --cells ref.cells 2>/dev/null || fail "dynmesh on world.dat"
    for p in 1 2 3 4; do same "$p" w.xyz --duplicates skip --edits w.edits --batch 10; done
    ;;
  *) fail "unknown case" ;;
esac
exit 0
