#!/usr/bin/env bash
# pip_install_test.sh PYTHON SOURCE_DIR WORK_DIR DYNMESH_CLI — the README's install command,
# as a user runs it: a new virtual environment that sees the system's packages, then
# `pip install --no-build-isolation .` in the repository, offline (--no-index), then
# install_check.py with that environment's python. The build backend builds into
# WORK_DIR/build (DYNMESH_WHEEL_BUILD_DIR) rather than the repository's build/python-wheel.
set -euo pipefail
python=$1 src=$2 work=$3 cli=$4
rm -rf "$work/venv" "$work/check" && mkdir -p "$work/check"
"$python" -m venv --system-site-packages "$work/venv"
cd "$src"
DYNMESH_WHEEL_BUILD_DIR="$work/build" PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 \
  "$work/venv/bin/pip" install --no-build-isolation --no-index . >"$work/pip.log" 2>&1 ||
  { tail -40 "$work/pip.log" >&2; exit 1; }
cd "$work/check"
"$work/venv/bin/python" "$src/tests/python/install_check.py" "$cli" "$work/check"
