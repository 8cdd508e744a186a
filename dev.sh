#!/usr/bin/env bash
# dev.sh: the project's entry point. Usage: bash dev.sh {deps|run [args]|test|asan|bench|fuzz [seconds]}
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$ROOT"
JOBS="${JOBS:-$(nproc 2>/dev/null || echo 2)}"

# Debian packages the project needs. gnuplot-nox is listed so that apt satisfies gnuplot's
# "gnuplot-qt | gnuplot-x11 | gnuplot-nox" without pulling in Qt. The python3-* packages
# build and test the Python module (pybind11, NumPy; pytest, meshio and matplotlib for its
# tests and example; venv and pip for the README's install command); pkg-config tests the
# installed dynmesh.pc. libopenmpi-dev and openmpi-bin build and run dynmesh-mpi (the quadtree
# on MPI ranks) and its tests. gnuplot-doc ships world.dat, a world coastline: real data the
# project did not write, which the MPI tests mesh on 1 to 4 ranks.
DEPS=(cmake g++ ninja-build libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev libgmp-dev
      libmpfr-dev libcgal-dev gnuplot gnuplot-nox clang libclang-rt-14-dev pkg-config
      python3 python3-dev python3-pybind11 pybind11-dev python3-numpy python3-pytest python3-meshio
      python3-matplotlib python3-venv python3-pip libopenmpi-dev openmpi-bin
      gnuplot-doc tetgen)

deps() {
  local missing=() p
  for p in "${DEPS[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
  done
  ((${#missing[@]} == 0)) && return 0
  echo "dev.sh: installing missing packages: ${missing[*]}" >&2
  local sudo=""
  [[ $(id -u) -eq 0 ]] || sudo=sudo
  # Wait (up to 10 minutes) for another apt or unattended-upgrades to release the dpkg lock
  # instead of failing at once.
  local lock=(-o DPkg::Lock::Timeout=600)
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get "${lock[@]}" update
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get "${lock[@]}" install -y --no-install-recommends "${missing[@]}" </dev/null
}

# build DIR [cmake args...]: configure with Ninja and build everything (tests, benchmarks).
build() {
  local dir=$1; shift
  cmake -S "$ROOT" -B "$dir" -G Ninja "$@"
  cmake --build "$dir" -j "$JOBS"
}

# build_release TARGET...: configure build/release (Release) and build only the TARGETs a
# job runs, not every test and benchmark.
build_release() {
  cmake -S "$ROOT" -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release
  cmake --build build/release -j "$JOBS" --target "$@"
}

# has_opt NAME ARGS...: true if ARGS contain NAME or NAME=...
has_opt() {
  local name=$1 a; shift
  for a in "$@"; do [[ $a == "$name" || $a == "$name="* ]] && return 0; done
  return 1
}

# ==== MAIN JOB: what `bash dev.sh run` runs. =============================================
# The dynmesh demo on its embedded input (20000 clustered points, 2000 updates): prints the
# figures and `verified: yes`, and draws the final tree to build/dynmesh-demo.svg (inside the
# ignored build/ tree). Arguments pass through (e.g. --n 100000 --updates 500 --svg tree.svg).
main_job() {
  local args=("$@")
  has_opt --svg "$@" || args+=(--svg build/dynmesh-demo.svg)
  build/release/bin/dynmesh demo "${args[@]}"
}
# ==========================================================================================

# Benchmark figures of bench/RESULTS.md: the list apps at n = 10^6, the sorts and hulls at
# n = 10^5 (their traces are 5-9 KB per element), then the dynamic quadtree against its static
# oracle (2D to 10^5, 3D to 10^5; the 10^6 row of RESULTS.md takes 14 GB and is run by hand).
# Extra arguments (e.g. --csv) go to every run.
bench_job() {
  build/release/bin/sac_suite --apps map,filter,reverse,minimum,sum,exptrees --n 1000000 \
    --updates 100 "$@"
  build/release/bin/sac_suite --apps quicksort,mergesort,quickhull,diameter --n 100000 \
    --updates 100 "$@"
  build/release/bin/dynmesh_bench --dim 2 --n 1000,10000,100000 --updates 1000 --reps 3 "$@"
  build/release/bin/dynmesh_bench --dim 3 --n 1000,10000,100000 --updates 1000 --reps 3 "$@"
}

cmd_run() { deps; build_release dynmesh_cli; main_job "$@"; }  # dynmesh_cli: bin/dynmesh

# The interpreter of the Python module and its tests: Debian's (whose pybind11, NumPy, pytest,
# meshio and matplotlib DEPS installs), not whichever python3 comes first on PATH. PYTHON
# overrides it.
PYTHON="${PYTHON:-/usr/bin/python3}"

cmd_test() {
  deps
  # RelWithDebInfo without -DNDEBUG: optimised, with debug info and assertions on. With the
  # Python module, whose pytest suite (tests/python/) runs with the rest.
  build build/debug -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g" \
    -DSAC_WARNINGS_AS_ERRORS=ON -DDYNMESH_PYTHON=ON -DPython3_EXECUTABLE="$PYTHON"
  ctest --test-dir build/debug --output-on-failure --no-tests=error -j "$JOBS"
}

cmd_asan() {
  deps
  local cxx=g++
  command -v clang++ >/dev/null && cxx=clang++
  build build/asan -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Debug -DSAC_SANITIZE=ON -DSAC_DEBUG_CHECKS=ON
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build/asan --output-on-failure --no-tests=error -j "$JOBS" -LE '^bench$'
}

cmd_bench() { deps; build_release sac_suite dynmesh_bench; bench_job "$@"; }  # what bench_job runs

# The libFuzzer targets of tests/fuzz/ (keep in step with tests/fuzz/CMakeLists.txt).
FUZZ_TARGETS=(fuzz_point_readers fuzz_edit_reader fuzz_dynamic_quadtree fuzz_dynamic_mesh fuzz_hpu_mesh fuzz_octree_mesh)

# fuzz [SECONDS]: clang build of the libraries and the fuzz targets only (no tests, tools or
# benchmarks) into build/fuzz, then each target for SECONDS (default 60) through its ctest
# test: a scratch corpus under build/fuzz seeded from tests/fuzz/corpus/<target>/, which is
# only read. Fails on any finding; the input is saved under build/fuzz/tests/fuzz/artifacts/.
cmd_fuzz() {
  local seconds=${1:-60}
  [[ $seconds =~ ^[1-9][0-9]*$ ]] || { echo "dev.sh fuzz: SECONDS must be a positive integer, got '$seconds'" >&2; exit 2; }
  deps
  cmake -S "$ROOT" -B build/fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DDYNMESH_FUZZ=ON -DDYNMESH_FUZZ_SECONDS="$seconds" \
    -DSAC_BUILD_TESTS=OFF -DSAC_BUILD_BENCH=OFF -DSAC_BUILD_EXAMPLES=OFF -DDYNMESH_BUILD_TOOLS=OFF
  cmake --build build/fuzz -j "$JOBS" --target "${FUZZ_TARGETS[@]}"
  # One target at a time: each is a single process on one core.
  ctest --test-dir build/fuzz -L '^fuzz$' --output-on-failure --no-tests=error
}

usage() {
  cat >&2 <<'USAGE'
usage: bash dev.sh COMMAND [args]
  deps         install missing Debian packages (apt-get; sudo when not root)
  run [args]   Release build of bin/dynmesh into build/release, then the main job (dynmesh demo [args])
  test         RelWithDebInfo build (asserts on, -Werror, the Python module) into build/debug, then every ctest test
  asan         Debug build with ASan+UBSan (clang++ if present) into build/asan, then ctest
  bench        Release build of the benchmarks, then sac_suite and dynmesh_bench at the README sizes
  fuzz [secs]  clang libFuzzer build into build/fuzz, then each fuzz target for secs (default 60)
USAGE
}

cmd=${1:-}
(($#)) && shift
case "$cmd" in
  deps) deps ;;
  run) cmd_run "$@" ;;
  test) cmd_test ;;
  asan) cmd_asan ;;
  bench) cmd_bench "$@" ;;
  fuzz) cmd_fuzz "$@" ;;
  -h|--help|help) usage ;;
  *) usage; exit 2 ;;
esac
