#!/usr/bin/env python3
"""Runs `bowl_mujoco.py` (MuJoCo) and `bowl predict --model bowl --json` on the same scenes and
prints two Markdown tables.

1. T: per-release T (or held) and the mean regime shares, and the mean T's difference, the model
   with restitution 0, 0.15 (the normal speed MuJoCo's critically damped contact still returns:
   e 0.13-0.15, impact_mujoco.py) and 0.5.
2. The regime, categorically per release: held (still inside at the horizon), or the mode it
   spent most of its time in (roll, slide, fly) and how it left (over the lip in flight, or in
   contact: rolling or sliding over the lip or a bare rim); the count of releases whose
   category is the same in both, the model at e 0 and at e 0.15.

The scenes: the rig's (60 deg, 75 mm bottom, ri 37.5 mm, granule 3 mm, mu_r 0.029, mu_s 0.4)
with the walls the model was first compared on, fillets (no impact at the corner), and scenes
chosen after the model's corner and contact code was last changed (45 deg tilt at 2 rad/s, a
70 deg 15 mm wall, a 5 mm fillet on it).

Usage: compare.py BOWL_BINARY PYTHON
"""
import json
import subprocess
import sys

BASE = dict(rim=0.075, ri=0.0375, a=0.003, mu_r=0.029, mu_s=0.4, rod=0.0)
AZ = [0, 90, 180, 270]
# name, tilt deg, w1 = w2 rad/s, wall angle deg, wall height m, fillet m, horizon s
SCENES = [
    ("bare rim", 60, 1.27, 90, 0.0, 0.0, 1.0),
    ("flared 60 deg, 10 mm", 60, 1.27, 60, 0.01, 0.0, 1.0),
    ("flared 60 deg, 20 mm", 60, 1.27, 60, 0.02, 0.0, 1.0),
    ("flared 60 deg, 20 mm", 60, 2.5, 60, 0.02, 0.0, 1.0),
    ("vertical, 20 mm", 60, 1.27, 90, 0.02, 0.0, 1.0),
    ("flared 60 deg, 20 mm, fillet 5 mm", 60, 1.27, 60, 0.02, 0.005, 1.0),
    ("flared 60 deg, 20 mm, fillet 10 mm", 60, 1.27, 60, 0.02, 0.01, 1.0),
    ("45 deg tilt, flared 60 deg, 20 mm", 45, 2.0, 60, 0.02, 0.0, 1.0),
    ("70 deg, 15 mm", 60, 2.0, 70, 0.015, 0.0, 1.0),
    ("45 deg tilt, 70 deg, 15 mm, fillet 5 mm", 45, 2.0, 70, 0.015, 0.005, 1.0),
]


def mujoco_run(th, w, alpha, h, fillet, horizon):
    b = BASE
    args = [w, w, th, b["rim"], b["ri"], b["a"], b["mu_r"], b["mu_s"], alpha, h, b["rod"],
            horizon, fillet] + AZ
    out = subprocess.run([PY, "tests/mujoco/bowl_mujoco.py"] + [str(x) for x in args],
                         check=True, capture_output=True, text=True).stdout
    rows = []
    for line in out.split("\n"):
        if line.strip():
            beta, t, roll, slide, fly, how = line.split()
            rows.append((None if t == "held" else float(t),
                         {"roll": float(roll), "slide": float(slide), "fly": float(fly)}, how))
    return rows


def ours(th, w, alpha, h, fillet, horizon, e):
    b = BASE
    cmd = [BOWL, "predict", "--model", "bowl", "--axes-angle-deg", str(th),
           "--precession-rad-s", str(w), "--spin-rad-s", str(w), "--rim-radius-m", str(b["rim"]),
           "--ri-m", str(b["ri"]), "--particle-radius-m", str(b["a"]), "--mu", str(b["mu_r"]),
           "--sliding-mu", str(b["mu_s"]), "--wall-angle-deg", str(alpha), "--wall-height-m",
           str(h), "--fillet-radius-m", str(fillet), "--restitution", str(e), "--max-time-s",
           str(horizon), "--release-azimuth-deg", ",".join(str(x) for x in AZ), "--json"]
    v = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return [(r["residence_time_s"], r["regime"],
             "held" if not r["left"] else ("flight" if r["left_in_flight"] else "contact"))
            for r in v["per_release"]]


def category(row):
    """held, or the dominant mode and how it left: 'slide, flight'."""
    t, regime, how = row
    if t is None:
        return "held"
    return f"{max(regime, key=lambda k: regime.get(k, 0.0))}, {how}"


def fmt_regime(r):
    return " ".join(f"{k} {v:.2f}" for k, v in sorted(r.items()) if v >= 0.005)


def mean(rows):
    ts = [r[0] for r in rows if r[0] is not None]
    return (sum(ts) / len(ts)) if len(ts) == len(rows) else None


def times(rows):
    return ", ".join("held" if r[0] is None else f"{r[0]:.4f}" for r in rows)


def avg_regime(rows):
    keys = {k for r in rows for k in r[1]}
    return {k: sum(r[1].get(k, 0.0) for r in rows) / len(rows) for k in keys}


def label(name, th, w):
    return f"{name} ({th} deg, {w} rad/s)"


def main():
    global BOWL, PY
    BOWL, PY = sys.argv[1], sys.argv[2]
    results = []
    print("| scene | MuJoCo T per release (s) | MuJoCo regime (mean) | bowl model e 0: T per release (s)"
          " | regime (mean) | mean T, model / MuJoCo - 1 | e 0.15: regime (mean) |"
          " mean T, model / MuJoCo - 1 | e 0.5: mean T, model / MuJoCo - 1 |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, th, w, alpha, h, fillet, horizon in SCENES:
        mj = mujoco_run(th, w, alpha, h, fillet, horizon)
        us = ours(th, w, alpha, h, fillet, horizon, 0.0)
        us15 = ours(th, w, alpha, h, fillet, horizon, 0.15)
        us5 = ours(th, w, alpha, h, fillet, horizon, 0.5)
        m_mj = mean(mj)

        def diff(rows):
            m = mean(rows)
            if m_mj and m:
                return f"{m:.4f} s, {100 * (m / m_mj - 1):+.1f} %"
            return "both held" if m_mj is None and all(r[0] is None for r in rows) else "differ"

        print(f"| {label(name, th, w)} | {times(mj)} | {fmt_regime(avg_regime(mj))} | {times(us)} | "
              f"{fmt_regime(avg_regime(us))} | {diff(us)} | {fmt_regime(avg_regime(us15))} | "
              f"{diff(us15)} | {diff(us5)} |", flush=True)
        results.append((label(name, th, w), mj, us, us15))

    print()
    print("| scene | MuJoCo per release | bowl model e 0 | same | bowl model e 0.15 | same |")
    print("| --- | --- | --- | --- | --- | --- |")
    total = same0 = same15 = 0
    for name, mj, us, us15 in results:
        c_mj = [category(r) for r in mj]
        c0 = [category(r) for r in us]
        c15 = [category(r) for r in us15]
        s0 = sum(a == b for a, b in zip(c_mj, c0))
        s15 = sum(a == b for a, b in zip(c_mj, c15))
        total += len(c_mj)
        same0 += s0
        same15 += s15
        print(f"| {name} | {'; '.join(c_mj)} | {'; '.join(c0)} | {s0}/{len(c_mj)} | "
              f"{'; '.join(c15)} | {s15}/{len(c_mj)} |", flush=True)
    print(f"| all | | | {same0}/{total} | | {same15}/{total} |")


if __name__ == "__main__":
    main()
