#!/usr/bin/env bash
# An independent rigid-body reference for the bowl model with a wall (issue 30): makes a Python
# venv with MuJoCo (pinned, from PyPI), builds `bowl`, runs tests/mujoco/compare.py on the
# scenes it names and prints the Markdown table docs/model.md §10 shows. Not part of tests/run:
# it downloads MuJoCo and takes a few minutes. Builds into $CARGO_TARGET_DIR when set.
# `compare.sh sweep [ARGS]` runs tests/mujoco/sweep.py instead (40 scenes drawn at random with a
# fixed seed, every release: about 30 minutes on two cores; its ARGS in its docstring).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
target=${CARGO_TARGET_DIR:-target}
venv=$target/mujoco-venv
if [ ! -x "$venv/bin/python" ]; then
  if ! python3 -m venv "$venv"; then
    echo "python3 -m venv failed: on Debian/Ubuntu install it with 'apt-get install python3-venv'" >&2
    exit 1
  fi
fi
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check mujoco==4.0.0 numpy==2.4.6
cargo build --release -q -p host-tools
if [ "${1:-}" = sweep ]; then
  shift
  exec "$venv/bin/python" tests/mujoco/sweep.py "$target/release/bowl" "$@"
fi
"$venv/bin/python" tests/mujoco/compare.py "$target/release/bowl" "$venv/bin/python"
