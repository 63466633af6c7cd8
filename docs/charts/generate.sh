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
  if ! cargo run --profile firmware -q -p qemu-tests --target thumbv7em-none-eabihf >"$log" 2>&1; then
    tail -n 20 "$log" >&2
    echo "QEMU run failed (log: $log); rerun with --no-qemu to chart without fresh counts" >&2
    exit 1
  fi
  grep -cE '^bench cost::' "$log" | sed 's/$/ cost benchmarks measured on the emulated Cortex-M4F/'
fi
qemu=()
if [ -f "$log" ]; then qemu=(--qemu-log "$log"); fi
cargo build --release -q -p host-tools
bowl=target/release/bowl
"$bowl" chart work-precision --out docs/charts/work-precision.svg "${qemu[@]}"
# The chooser's cost table, fitted to those measurements (model-core/src/choose/cost_table.rs).
"$bowl" chart costs --csv docs/charts/work-precision.csv --out model-core/src/choose/cost_table.rs
# The chooser's error table over spin-ups (model-core/src/choose/error_table.bin, ~7 s), then
# the tools rebuilt on both tables before the chooser is charted.
"$bowl" chart error-table --out model-core/src/choose/error_table.bin
cargo build --release -q -p host-tools
"$bowl" chart chooser --out docs/charts/chooser.svg
for c in radial velocity residence stability; do
  "$bowl" chart "$c" --out "docs/charts/$c.svg"
done
# The control loop's figures on the simulated rig (docs/control.md).
"$bowl" chart settling --out docs/charts/control-settling.svg
"$bowl" chart control-stability --out docs/charts/control-stability.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --out docs/charts/control-family.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --target-rad-s 0.5 --out docs/charts/control-family-low.svg
# From rest to 1 rad/s, the start the issue's tightest targets name (docs/control.md, "Transitions").
"$bowl" chart family --rig-file tests/rigs/family-60.toml --target-rad-s 1 --out docs/charts/control-family-1.svg
# Slowing down while running (docs/control.md, "Transitions").
"$bowl" chart family --rig-file tests/rigs/family-60.toml --from-rad-s 3 --target-rad-s 1 --out docs/charts/control-family-down.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --from-rad-s 3 --target-rad-s 0.5 --out docs/charts/control-family-down-low.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --target-rad-s 1 --current-sense --out docs/charts/control-family-1-current.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --target-rad-s 0.5 --current-sense --out docs/charts/control-family-low-current.svg
"$bowl" chart family --rig-file tests/rigs/family-60.toml --from-rad-s 3 --target-rad-s 0.5 --current-sense --out docs/charts/control-family-down-low-current.svg
# The rolling model of the tilted, precessing bowl (docs/model.md section 9).
mkdir -p docs/charts/rolling
"$bowl" chart rolling-residence --out docs/charts/rolling/residence-60.svg
"$bowl" chart rolling-residence --axes-angle-deg 30 --out docs/charts/rolling/residence-30.svg
"$bowl" chart rolling-paths --out docs/charts/rolling/paths.svg
"$bowl" chart rolling-hierarchy --out docs/charts/rolling/hierarchy.svg
"$bowl" chart rolling-hierarchy --mu 0.001 --out docs/charts/rolling/hierarchy-mu0.001.svg
"$bowl" chart rolling-hierarchy --mu 0.1 --out docs/charts/rolling/hierarchy-mu0.1.svg
"$bowl" chart rolling-work-precision --out docs/charts/rolling/work-precision.svg
# The granule in the real bowl: sliding, the wall and its lip (docs/model.md section 10).
mkdir -p docs/charts/bowl
"$bowl" chart bowl-residence --out docs/charts/bowl/residence-60.svg
"$bowl" chart bowl-residence --axes-angle-deg 30 --out docs/charts/bowl/residence-30.svg
"$bowl" chart bowl-regimes --out docs/charts/bowl/regimes.svg
"$bowl" chart bowl-regime-map --out docs/charts/bowl/regime-map.svg
"$bowl" chart bowl-work-precision --out docs/charts/bowl/work-precision.svg
"$bowl" chart hierarchy-work-precision --out docs/charts/bowl/hierarchy-work-precision.svg
