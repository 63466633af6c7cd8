#!/usr/bin/env bash
# Regenerates every chart in docs/charts/ (SVG, PNG and the CSV behind each).
# Usage: docs/charts/generate.sh [--no-qemu]
#   Without --no-qemu it first runs the shared benchmarks on the emulated Cortex-M4F (QEMU) and
#   puts their instruction counts on the work-precision chart; with it, it reuses
#   target/test-logs/qemu-cases.log if present (tests/run writes it).
# The scipy side-by-side is separate (it downloads scipy): tests/scipy/compare.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
log=target/test-logs/qemu-cases.log
mkdir -p target/test-logs
if [ "${1:-}" != "--no-qemu" ]; then
  cargo run --release -q -p qemu-tests --target thumbv7em-none-eabihf | tee "$log" | grep -E '^bench cost::' || true
fi
qemu=()
if [ -f "$log" ]; then qemu=(--qemu-log "$log"); fi
cargo build --release -q -p host-tools
bowl=target/release/bowl
"$bowl" chart work-precision --out docs/charts/work-precision.svg "${qemu[@]}"
for c in radial velocity residence stability; do
  "$bowl" chart "$c" --out "docs/charts/$c.svg"
done
