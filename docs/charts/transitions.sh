#!/usr/bin/env bash
# The transition matrix of docs/control.md: every change between rest, the lowest speed, 0.5, 1,
# 2, 3 and 4 rad/s on a family file, each plant commissioned, loaded with material, settled at the
# first speed and then commanded to the second (`bowl sim family --from-rad-s A --target-rad-s B`).
# Prints one markdown row per change: false faults, overshoot shares and worst, settling shares.
#
#   bash docs/charts/transitions.sh tests/rigs/family-60.toml            # the whole matrix
#   bash docs/charts/transitions.sh F "3 1" "3 0.5" "0 0.5"              # only these changes
#   BOWL=path/to/bowl bash docs/charts/transitions.sh F                  # another build
#   SIM_FLAGS=--current-sense bash docs/charts/transitions.sh F          # with current sense
#
# "low" stands for the family's lowest speed: the highest over its plants of 0.2 rad/s and one
# pulse per 4 s (docs/control.md).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
file=$1
shift
bowl=${BOWL:-target/release/bowl}
[ -x "$bowl" ] || cargo build --release -p host-tools >&2
low=$(python3 - "$file" <<'PY'
import math, sys, tomllib
d = tomllib.load(open(sys.argv[1], "rb"))
plants = d.get("plant", [d])
n = [p.get(axis, {}).get("pulses_per_rev", 12) for p in plants for axis in ("precession", "spin")]
print(f"{max(0.2, max(2 * math.pi / (k * 4.0) for k in n)):.3f}")
PY
)
if [ $# -gt 0 ]; then
  changes=("$@")
else
  changes=()
  for a in 0 low 0.5 1 2 3 4; do
    for b in low 0.5 1 2 3 4; do
      [ "$a" != "$b" ] && changes+=("$a $b")
    done
  done
fi
echo "| change, rad/s | false faults | overshoot <= 5 % | <= 10 % | worst % | 2 % settled <= 3 s | 5 % settled <= 10 s | <= 8 s | never settled (of them saturated) | ripple median / worst % |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for c in "${changes[@]}"; do
  read -r a b <<<"$c"
  [ "$a" = low ] && a=$low
  [ "$b" = low ] && b=$low
  # shellcheck disable=SC2086
  "$bowl" sim family --rig-file "$file" --from-rad-s "$a" --target-rad-s "$b" ${SIM_FLAGS:-} --json |
    python3 -c '
import json, sys
d = json.load(sys.stdin)
s = d["summary"]
s["change"] = "%g -> %g" % (d["from_rad_s"], d["target_rad_s"])
print("| {change} | {false_faults} / {plants} | {overshoot_within_5_pct_share:.1f} % "
      "| {overshoot_within_10_pct_share:.1f} % | {overshoot_worst_pct:.1f} "
      "| {settled_2pct_within_3_s_share:.1f} % | {settled_5pct_within_10_s_share:.1f} % "
      "| {settled_5pct_within_8_s_share:.1f} % | {never_settled} ({saturated_axes}) "
      "| {ripple_median_pct:.2f} / {ripple_worst_pct:.2f} |".format(**s))
'
done
