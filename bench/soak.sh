#!/usr/bin/env bash
# soak.sh — the soak run of bench/RESULTS.md ("Soak run"): dynmesh_soak, 10^6 single-point
# updates in 2D, then in 3D (one after the other, never in parallel: the RSS samples and the
# times assume the process has a core to itself), each under `/usr/bin/time -v` for the
# peak RSS. Logs land in $OUT (default build/soak/): soak_2d.log, soak_3d.log with the
# program's output followed by time's report. Exit status: non-zero if either run found a
# mismatch.
#
# Usage: bash bench/soak.sh [extra dynmesh_soak options, e.g. --updates 100000]
#        (after `bash dev.sh run`, which builds; SOAK=path/to/dynmesh_soak to override)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
BIN=${SOAK:-build/release/bin/dynmesh_soak}
OUT=${OUT:-build/soak}
mkdir -p "$OUT"
status=0
for dim in 2 3; do
  log="$OUT/soak_${dim}d.log"
  echo "== $BIN --dim $dim $* > $log"
  if ! /usr/bin/time -v "$BIN" --dim "$dim" "$@" >"$log" 2>&1; then status=1; fi
  grep -E '^# |Maximum resident|Elapsed \(wall' "$log"
done
exit $status
