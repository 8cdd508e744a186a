#!/usr/bin/env bash
# tests/mpi/mpi_test.sh CASE MPIEXEC DYNMESH DYNMESH_MPI MPI_GEN WORK_DIR [UNIT] —
# end-to-end tests of `dynmesh-mpi quadtree` (docs/FORMATS.md, docs/DISTRIBUTED.md): its
# `.cells` must equal `dynmesh quadtree`'s byte for byte for every number of ranks; bad input
# gives one line of ours from rank 0 and a non-zero status on every rank, within a timeout.
# The cases differential2 and differential3 run UNIT (mpi_quadtree_test) on 2 and 3 ranks;
# merge1/merge3 and number1/number3 run the writers' own tests (merge_on_root_test,
# number_on_root_test, passed in its place) on 1 and 3 ranks. One ctest
# per CASE (tests/mpi/CMakeLists.txt). Exit 0 pass, 1 fail.
#
# Every launch is isolated and judged apart from the launcher:
# - OpenMPI keeps a session directory per user and node; launchers that start and end together
#   race on it (open-mpi/ompi issue 8510), so each test gets a fresh one of its own.
# - Each rank appends its own exit status to status.txt, so a launch that failed (mpiexec ran
#   fewer ranks to the end, or exited non-zero after they all did) is reported as the
#   launcher's failure, not as a wrong tree.
# - On stderr, only our lines are asserted. The launcher and the libraries it loads (hwloc,
#   ORTE, PMIx) may print notices of their own, on every rank; see our_lines below.
set -uo pipefail

case_name=$1 mpiexec=$2 dynmesh=$3 dmpi=$4 gen=$5 work=$6 unit=${7:-}
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
export DYNMESH_PROGRESS_DELAY_MS=3600000

fail() {
  echo "FAIL [$case_name]: $*" >&2
  exit 1
}

# A session directory of this test's own, under /tmp: OpenMPI puts Unix sockets in it, whose
# paths must stay short (about 100 bytes), so it is not under the build tree.
session=$(mktemp -d /tmp/sac-mpi.XXXXXX) || fail "mktemp"
trap 'rm -rf "$session"' EXIT
export OMPI_MCA_orte_tmpdir_base=$session TMPDIR=$session
limit=600

# launch P PROGRAM ARGS...: PROGRAM on P ranks (more ranks than cores: --oversubscribe; -q: no
# launcher chatter), stdout to out.txt and stderr to err.txt, killed after `limit` seconds so
# that a hang fails instead of blocking. The limit is for hangs, not speed: a launch takes a
# few seconds, but four ranks on two loaded cores have taken over two minutes. Sets
# `statuses` to the ranks' exit statuses, sorted. Fails the test on a hang or a failed
# launch; returns 0 when every rank exited 0, 1 otherwise.
launch() {
  local p=$1
  shift
  rm -f status.txt
  timeout "$limit" "$mpiexec" -q --oversubscribe -np "$p" sh -c '"$0" "$@"; echo "$?" >>status.txt' "$@" \
    >out.txt 2>err.txt
  local rc=$?
  ((rc != 124)) || fail "timed out after $limit s (a rank hangs): -np $p ${*:2}"
  statuses=$(sort -n status.txt 2>/dev/null)
  local done=0
  [[ -z $statuses ]] || done=$(wc -l <<<"$statuses")
  if ((done != p || rc != 0)); then
    cat err.txt >&2
    fail "the launcher failed, not the program: mpiexec exited $rc and $done of $p ranks ran to the end: -np $p ${*:2}"
  fi
  [[ $(uniq <<<"$statuses") == 0 ]]
}

# mpi P ARGS...: dynmesh-mpi ARGS on P ranks; as launch.
mpi() {
  local p=$1
  shift
  launch "$p" "$dmpi" "$@"
}

# our_lines NOISE ERR: the lines of ERR that are ours, that is, all but the launcher's notices.
# A notice is a line NOISE holds (what the same launcher printed on stderr for a run of ours
# that printed nothing: hwloc's warnings, for one, come from every rank), a line of hwloc's
# ("[hwloc..."), of ORTE's or PMIx's (they open with "[host:pid]" or name themselves), or a
# line of one of OpenMPI's help boxes (between two rules of dashes).
our_lines() {
  awk -v noise="$1" '
    BEGIN { while ((getline line < noise) > 0) known[line] = 1 }
    /^--------------------+$/ { inbox = !inbox; next }
    inbox { next }
    $0 in known { next }
    /^\[hwloc/ || /^\[[^] ]+:[0-9]+\]/ || /ORTE_ERROR_LOG|PMIX ERROR|PMIx/ { next }
    { print }' "$2"
}

# same P POINTS ARGS...: dynmesh-mpi on P ranks writes the .cells that dynmesh wrote to ref.cells.
same() {
  local p=$1
  shift
  mpi "$p" quadtree "$@" --cells mpi.cells || { cat err.txt >&2; fail "a rank failed ($(tr '\n' ' ' <<<"$statuses")): -np $p $*"; }
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

# expect_error WANT_TEXT ARGS...: on 3 ranks, every rank exits non-zero, our stderr is exactly
# one line "dynmesh-mpi: ..." containing WANT_TEXT (and dynmesh's own message), no .cells.
# noise.txt must hold the launcher's notices (errors_case writes it).
expect_error() {
  local want=$1
  shift
  rm -f err.cells
  mpi 3 quadtree "$@" --cells err.cells && fail "every rank exited 0: $*"
  grep -qx 0 <<<"$statuses" && fail "a rank exited 0: $*"
  our_lines noise.txt err.txt >ours.txt
  [[ $(wc -l <ours.txt) -eq 1 ]] || { cat err.txt >&2; fail "our stderr is not exactly one line: $*"; }
  grep -q '^dynmesh-mpi: ' ours.txt || fail "stderr does not start with 'dynmesh-mpi: ': $(cat ours.txt)"
  grep -qF -- "$want" ours.txt || fail "stderr lacks '$want': $(cat ours.txt)"
  [[ ! -e err.cells ]] || fail "a failed run wrote its output: $*"
  # The message is dynmesh quadtree's.
  "$dynmesh" quadtree "$@" --cells err1.cells >/dev/null 2>err1.txt && fail "dynmesh quadtree accepted $*"
  [[ "$(sed 's/^dynmesh-mpi: //' ours.txt)" == "$(sed 's/^dynmesh: //' err1.txt)" ]] ||
    fail "message differs from dynmesh quadtree's: $(cat ours.txt) / $(cat err1.txt)"
}

# same_mesh P POINTS ARGS...: dynmesh-mpi mesh on P ranks writes the ref.node, ref.ele,
# ref.feed, ref.vtk and ref.msh that dynmesh mesh wrote.
same_mesh() {
  local p=$1
  shift
  mpi "$p" mesh "$@" -o mpi --feed mpi.feed --vtk mpi.vtk --msh mpi.msh ||
    { cat err.txt >&2; fail "a rank failed ($(tr '\n' ' ' <<<"$statuses")): -np $p mesh $*"; }
  for f in node ele vtk msh; do cmp -s ref.$f mpi.$f || fail "-np $p mesh $*: .$f differs from dynmesh mesh's"; done
  cmp -s ref.feed mpi.feed || fail "-np $p mesh $*: the feed differs from dynmesh mesh's"
}

# exact_mesh DIM DIST N SPREAD NEDITS [ARGS...]: generated input and edits; 1 to 4 ranks with
# batches, 2 ranks with single edits, against dynmesh mesh (the quadtree mesh in 2D). The
# array `mpi_only` holds options for dynmesh-mpi alone (--partition-level).
exact_mesh() {
  local dim=$1 dist=$2 n=$3 spread=$4 nedits=$5
  shift 5
  "$gen" "$dist" "$dim" "$n" 7 "$spread" in.xyz in.edits "$nedits" || fail "mpi_gen $dist"
  "$dynmesh" mesh in.xyz --dim "$dim" --postprocess quadtree --edits in.edits --batch 9 -o ref --feed ref.feed --vtk ref.vtk --msh ref.msh "$@" \
    2>/dev/null || fail "dynmesh mesh $dist"
  for p in 1 2 3 4; do
    same_mesh "$p" in.xyz --dim "$dim" --postprocess quadtree --edits in.edits --batch 9 "$@" "${mpi_only[@]}"
  done
  "$dynmesh" mesh in.xyz --dim "$dim" --postprocess quadtree --edits in.edits -o ref --feed ref.feed --vtk ref.vtk --msh ref.msh "$@" \
    2>/dev/null || fail "dynmesh mesh $dist"
  same_mesh 2 in.xyz --dim "$dim" --postprocess quadtree --edits in.edits "$@" "${mpi_only[@]}"
}
mpi_only=()

# expect_mesh_error WANT_TEXT ARGS...: as expect_error, for dynmesh-mpi mesh against dynmesh
# mesh --postprocess quadtree: one line of ours, every rank non-zero, no output written.
expect_mesh_error() {
  local want=$1
  shift
  rm -f err.node err.ele err.feed
  mpi 3 mesh "$@" --postprocess quadtree -o err --feed err.feed && fail "every rank exited 0: mesh $*"
  grep -qx 0 <<<"$statuses" && fail "a rank exited 0: mesh $*"
  our_lines noise.txt err.txt >ours.txt
  [[ $(wc -l <ours.txt) -eq 1 ]] || { cat err.txt >&2; fail "our stderr is not exactly one line: mesh $*"; }
  grep -qF -- "$want" ours.txt || fail "stderr lacks '$want': $(cat ours.txt)"
  [[ ! -e err.node && ! -e err.ele && ! -e err.feed ]] || fail "a failed run wrote its output: mesh $*"
  "$dynmesh" mesh "$@" --postprocess quadtree -o err1 >/dev/null 2>err1.txt && fail "dynmesh mesh accepted $*"
  [[ "$(sed 's/^dynmesh-mpi: //' ours.txt)" == "$(sed 's/^dynmesh: //' err1.txt | grep -v '^\[dynmesh\]')" ]] ||
    fail "message differs from dynmesh mesh's: $(cat ours.txt) / $(cat err1.txt)"
}

# errors_case: malformed, NaN, duplicate, outside the box, absent deletion, spread beyond the
# resolution; first the launcher's notices of a clean run, and our_lines's own check.
errors_case() {
  "$gen" uniform 2 300 3 2 s.xyz s.edits 20 || fail "mpi_gen"
  mpi 3 quadtree s.xyz --edits s.edits --cells ok.cells || { cat err.txt >&2; fail "a clean run failed"; }
  grep '^dynmesh-mpi' err.txt && fail "a clean run printed a line of ours on stderr"
  cp err.txt noise.txt
  # our_lines keeps our lines and any line it cannot place, and drops the launcher's.
  printf '[hwloc/linux] a notice\n[host:42] [[1,0],0] ORTE_ERROR_LOG: x\n%s\nOpen MPI: in a box\n%s\n' \
    ---------------------------------------- ---------------------------------------- >notices.txt
  { cat notices.txt; echo "dynmesh-mpi: one"; cat notices.txt; } >e1.txt
  [[ $(our_lines noise.txt e1.txt) == "dynmesh-mpi: one" ]] || fail "our_lines lost our line or kept a notice"
  { cat e1.txt; echo "a second line"; } >e2.txt
  [[ $(our_lines noise.txt e2.txt | wc -l) -eq 2 ]] || fail "our_lines dropped a line that is not the launcher's"
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
  # An output that cannot be written: rank 0 finds it before the leaves merge, which still
  # runs to its end, so no rank waits forever; one line of ours, every rank non-zero.
  mpi 3 quadtree s.xyz --cells nodir/x.cells && fail "writing into a missing directory succeeded"
  grep -qx 0 <<<"$statuses" && fail "a rank exited 0 on an output it cannot write"
  our_lines noise.txt err.txt >ours.txt
  [[ $(wc -l <ours.txt) -eq 1 ]] && grep -qF "nodir/x.cells" ours.txt ||
    { cat err.txt >&2; fail "an unwritable output: not one line of ours naming the file: $(cat ours.txt)"; }
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
    mpi 3 quadtree u.xyz --edits u.edits --ghost-ring 0 --cells narrow.cells || fail "ring 0 failed to run"
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
      [[ $(grep -c '^\[dynmesh-mpi\] rank [0-9]*: .*, peak_rss [0-9]* MiB$' err.txt) -eq $p ]] ||
        { cat err.txt >&2; fail "-np $p --stats: not a line with peak_rss for every rank"; }
    done
    # The writing's own peak (hidden --measure-writing), on every rank's line.
    same 3 u.xyz --box 0 0 1 --edits move.edits --batch 50 --stats --measure-writing
    [[ $(grep -c ', peak_rss [0-9]* MiB, writing peak_rss [0-9]* MiB (from [0-9]* MiB)$' err.txt) -eq 3 ]] ||
      { cat err.txt >&2; fail "--measure-writing: not a writing peak on every rank's line"; }
    same 2 u.xyz --box 0 0 1 --edits move.edits --batch 50 --rebalance 0
    ;;
  errors) # bad input: one line of ours from rank 0, every rank non-zero, nothing written
    errors_case
    ;;
  errors_hwloc) # the same where hwloc warns on every rank (no sysfs, as in a minimal container)
    mkdir -p no-sysfs
    export HWLOC_FSROOT=$PWD/no-sysfs
    errors_case
    grep -q hwloc noise.txt || fail "hwloc printed no warning: the case no longer shows the launcher's notices"
    ;;
  differential2 | differential3) # MpiQuadtree against StaticQuadtree after every batch
    [[ -x $unit ]] || fail "no mpi_quadtree_test given"
    launch "${case_name#differential}" "$unit" || { cat out.txt err.txt >&2; fail "mpi_quadtree_test failed"; }
    cat out.txt
    ;;
  merge1 | merge3 | number1 | number3) # the writers' streamed merges on rank 0 (UNIT: their test)
    [[ -x $unit ]] || fail "no unit test given"
    launch "${case_name: -1}" "$unit" || { cat out.txt err.txt >&2; fail "$(basename "$unit") failed"; }
    cat out.txt
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
  mesh_exact2d) # the quadtree mesh: uniform in the unit box (root cells finer than the default
    # box allows), clusters, shrinking (spread 2^30), spiral, boundary; the feed too
    mpi_only=(--partition-level 6)
    exact_mesh 2 uniform 3000 2 200 --box 0 0 1
    mpi_only=()
    exact_mesh 2 clusters 1200 2 150
    exact_mesh 2 shrinking 1200 1073741824 150
    exact_mesh 2 spiral 1200 2 150
    mpi_only=(--partition-level 5)
    exact_mesh 2 boundary 800 2 100
    ;;
  mesh_exact3d) # the octree's tetrahedral mesh
    mpi_only=(--partition-level 4)
    exact_mesh 3 uniform 400 2 60 --box 0 0 0 1
    mpi_only=()
    exact_mesh 3 clusters 300 2 60
    exact_mesh 3 spiral 300 2 60
    ;;
  mesh_ghost_ring) # the meshes' ring (docs/DISTRIBUTED.md): one narrower breaks exactness here
    "$gen" uniform 3 800 3 2 t.xyz t.edits 100 || fail "mpi_gen"
    "$dynmesh" mesh t.xyz --box 0 0 0 1 --edits t.edits --batch 3 -o ref --feed ref.feed --vtk ref.vtk --msh ref.msh 2>/dev/null || fail "dynmesh mesh"
    same_mesh 3 t.xyz --box 0 0 0 1 --edits t.edits --batch 3 --partition-level 4
    mpi 3 mesh t.xyz --box 0 0 0 1 --edits t.edits --batch 3 --partition-level 4 --ghost-ring 2 -o narrow \
      --feed narrow.feed || fail "ring 2 failed to run"
    cmp -s ref.ele narrow.ele && cmp -s ref.feed narrow.feed &&
      fail "a ghost ring of width 2 gave the exact mesh: the test input no longer shows the need"
    ;;
  mesh_real_world) # gnuplot's world coastline, meshed on 1 to 4 ranks
    world=/usr/share/doc/gnuplot/examples/world.dat
    [[ -r $world ]] || fail "$world is missing (bash dev.sh deps installs gnuplot-doc)"
    grep -v '^#' "$world" | awk 'NF >= 2 { print $1, $2 }' >w.xyz
    awk '!seen[$0]++' w.xyz | awk 'NR % 7 == 1 { print "- " $0 } NR % 14 == 1 { keep[++k] = $0 }
      END { for (i = 1; i <= k; i++) print "+ " keep[i] }' >w.edits
    "$dynmesh" mesh w.xyz --postprocess quadtree --duplicates skip --edits w.edits --batch 10 -o ref --feed ref.feed \
      --vtk ref.vtk --msh ref.msh \
      >/dev/null 2>&1 || fail "dynmesh mesh on world.dat"
    for p in 1 2 3 4; do same_mesh "$p" w.xyz --postprocess quadtree --duplicates skip --edits w.edits --batch 10; done
    ;;
  mesh_errors) # bad input to dynmesh-mpi mesh: one line of ours, every rank non-zero, nothing written
    "$gen" uniform 2 300 3 2 s.xyz s.edits 20 || fail "mpi_gen"
    mpi 3 mesh s.xyz --postprocess quadtree --edits s.edits -o ok || { cat err.txt >&2; fail "a clean run failed"; }
    grep '^dynmesh-mpi' err.txt && fail "a clean run printed a line of ours on stderr"
    cp err.txt noise.txt
    printf '0.5 0.5\n0.5 abc\n' >bad.xyz
    printf '0.5 0.5\n0.1 0.2\n0.5 0.5\n' >dup.xyz
    echo "- 0.123 0.456" >absent.edits
    echo "+ 5 5" >outside.edits
    { head -4 s.edits; echo "- 0.123 0.456"; } >late.edits
    expect_mesh_error "malformed number" bad.xyz
    expect_mesh_error "duplicate point" dup.xyz
    expect_mesh_error "not in the set" s.xyz --edits absent.edits
    expect_mesh_error "late.edits:5:" s.xyz --edits late.edits --batch 3
    expect_mesh_error "outside the domain box" s.xyz --edits outside.edits
    # The hpu mesh (the 2D default) does not run on ranks yet: refused, status 2.
    mpi 3 mesh s.xyz -o hpu && fail "the hpu mesh ran on ranks"
    our_lines noise.txt err.txt | grep -q "does not run on ranks yet" || { cat err.txt >&2; fail "hpu: no clear refusal"; }
    [[ ! -e hpu.node ]] || fail "the refused hpu run wrote its output"
    # An output that cannot be written: one line naming it, every rank non-zero.
    mpi 3 mesh s.xyz --postprocess quadtree -o nodir/x && fail "writing into a missing directory succeeded"
    grep -qx 0 <<<"$statuses" && fail "a rank exited 0 on an output it cannot write"
    our_lines noise.txt err.txt >ours.txt
    [[ $(wc -l <ours.txt) -eq 1 ]] && grep -qF "nodir/x" ours.txt ||
      { cat err.txt >&2; fail "an unwritable output: not one line of ours naming the file: $(cat ours.txt)"; }
    ;;
  mesh_differential2 | mesh_differential3) # MpiMesh against the static twins after every batch
    [[ -x $unit ]] || fail "no mpi_mesh_test given"
    launch "${case_name#mesh_differential}" "$unit" || { cat out.txt err.txt >&2; fail "mpi_mesh_test failed"; }
    cat out.txt
    ;;
  *) fail "unknown case" ;;
esac
exit 0
