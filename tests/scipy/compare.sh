#!/usr/bin/env bash
# Side by side with scipy: one run makes a Python venv (numpy, scipy from PyPI), has `bowl`
# measure our integrators (CSV), runs scipy.integrate.solve_ivp (RK45, DOP853) with a terminal
# event at r = R on the same scenes, and writes docs/charts/scipy-comparison.{md,csv} plus the
# charts docs/charts/scipy-comparison{,-time}.{svg,png}; then the batch closed forms beside
# vectorised numpy (tests/scipy/batch.py: docs/charts/batch-throughput.{md,json}).
# Not part of tests/run: it downloads scipy. Usage: tests/scipy/compare.sh [--quick | --batch-only]
# (--batch-only: the batch closed forms beside numpy alone). Builds into $CARGO_TARGET_DIR when set.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
target=${CARGO_TARGET_DIR:-target}
venv=$target/scipy-venv
if [ ! -x "$venv/bin/python" ]; then
  if ! python3 -m venv "$venv"; then
    echo "python3 -m venv failed: on Debian/Ubuntu install it with 'apt-get install python3-venv'" >&2
    exit 1
  fi
fi
packages="numpy scipy"
[ "${1:-}" = "--batch-only" ] && packages=numpy
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check $packages
mkdir -p "$target/scipy"
cargo build --release -q -p host-tools
bowl=$target/release/bowl
if [ "${1:-}" = "--batch-only" ]; then
  "$venv/bin/python" tests/scipy/batch.py "$bowl" docs/charts/batch-throughput
  exit 0
fi
"$bowl" chart work-precision --csv-only --families closed,rk4,dp54 \
  --out "$target/scipy/ours.svg" ${1:+--quick}
"$venv/bin/python" tests/scipy/compare.py "$target/scipy/ours.csv" docs/charts/scipy-comparison
"$bowl" chart scipy --csv docs/charts/scipy-comparison.csv --out docs/charts/scipy-comparison.svg
# Batch closed forms beside vectorised numpy on the same scenes, in the same run
# (docs/charts/batch-throughput.{md,json}; docs/model.md, "Batch throughput").
"$venv/bin/python" tests/scipy/batch.py "$bowl" docs/charts/batch-throughput
