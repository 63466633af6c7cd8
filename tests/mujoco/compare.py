#!/usr/bin/env python3
"""Runs `bowl_mujoco.py` (MuJoCo) and `bowl predict --model bowl --json` on the same scenes and
prints a Markdown table: per-release T (or held) and regime, and the mean T's difference, the
model with restitution 0 (MuJoCo's contact is critically damped), 0.15 (the normal speed MuJoCo
returns at the 60 deg corner: 0.60 m/s in, 0.085 m/s out at 1.27 rad/s, release 0 deg) and 0.5.

Usage: compare.py BOWL_BINARY PYTHON
"""
import json
import subprocess
import sys

BOWL, PY = sys.argv[1], sys.argv[2]
# The rig's scene: 60 deg, 75 mm bottom, ri 37.5 mm, granule 3 mm, mu_r 0.029, mu_s 0.4.
BASE = dict(th=60, rim=0.075, ri=0.0375, a=0.003, mu_r=0.029, mu_s=0.4, rod=0.0)
AZ = [0, 90, 180, 270]
# name, w1 = w2, wall angle, wall height, horizon
SCENES = [
    ("bare rim", 1.27, 90, 0.0, 1.0),
    ("flared 60 deg, 10 mm", 1.27, 60, 0.01, 1.0),
    ("flared 60 deg, 20 mm", 1.27, 60, 0.02, 1.0),
    ("flared 60 deg, 20 mm", 2.5, 60, 0.02, 1.0),
    ("vertical, 20 mm", 1.27, 90, 0.02, 1.0),
]


def mujoco_run(w, alpha, h, horizon):
    b = BASE
    args = [w, w, b["th"], b["rim"], b["ri"], b["a"], b["mu_r"], b["mu_s"], alpha, h, b["rod"],
            horizon] + AZ
    out = subprocess.run([PY, "tests/mujoco/bowl_mujoco.py"] + [str(x) for x in args],
                         check=True, capture_output=True, text=True).stdout
    rows = []
    for line in out.split("\n"):
        if line.strip():
            beta, t, roll, slide, fly = line.split()
            rows.append((None if t == "held" else float(t),
                         {"roll": float(roll), "slide": float(slide), "fly": float(fly)}))
    return rows


def ours(w, alpha, h, horizon, e):
    b = BASE
    cmd = [BOWL, "predict", "--model", "bowl", "--axes-angle-deg", str(b["th"]),
           "--precession-rad-s", str(w), "--spin-rad-s", str(w), "--rim-radius-m", str(b["rim"]),
           "--ri-m", str(b["ri"]), "--particle-radius-m", str(b["a"]), "--mu", str(b["mu_r"]),
           "--sliding-mu", str(b["mu_s"]), "--wall-angle-deg", str(alpha), "--wall-height-m",
           str(h), "--restitution", str(e), "--max-time-s", str(horizon),
           "--release-azimuth-deg", ",".join(str(x) for x in AZ), "--json"]
    v = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return [(r["residence_time_s"], r["regime"]) for r in v["per_release"]]


def fmt_regime(r):
    return " ".join(f"{k} {v:.2f}" for k, v in sorted(r.items()) if v >= 0.005)


def mean(rows):
    ts = [t for t, _ in rows if t is not None]
    return (sum(ts) / len(ts)) if len(ts) == len(rows) else None


print("| scene | \\|w1\\| = \\|w2\\| rad/s | MuJoCo T per release (s) | MuJoCo regime (mean) |"
      " bowl model e 0: T per release (s) | regime (mean) | mean T, model / MuJoCo - 1 |"
      " e 0.15: mean T, model / MuJoCo - 1 | e 0.5: mean T, model / MuJoCo - 1 |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for name, w, alpha, h, horizon in SCENES:
    mj = mujoco_run(w, alpha, h, horizon)
    us = ours(w, alpha, h, horizon, 0.0)
    us15 = ours(w, alpha, h, horizon, 0.15)
    us5 = ours(w, alpha, h, horizon, 0.5)

    def times(rows):
        return ", ".join("held" if t is None else f"{t:.4f}" for t, _ in rows)

    def avg_regime(rows):
        keys = {k for _, r in rows for k in r}
        return {k: sum(r.get(k, 0.0) for _, r in rows) / len(rows) for k in keys}

    m_mj = mean(mj)

    def diff(rows):
        m = mean(rows)
        if m_mj and m:
            return f"{m:.4f} s, {100 * (m / m_mj - 1):+.1f} %"
        return "both held" if m_mj is None and m is None else "differ"

    print(f"| {name} | {w} | {times(mj)} | {fmt_regime(avg_regime(mj))} | {times(us)} | "
          f"{fmt_regime(avg_regime(us))} | {diff(us)} | {diff(us15)} | {diff(us5)} |", flush=True)
