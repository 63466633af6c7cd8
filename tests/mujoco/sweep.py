#!/usr/bin/env python3
"""A randomized held-out comparison of `bowl predict --model bowl` with MuJoCo (issue 30's
targets on scenes nobody tuned the model on): draws scenes with a fixed seed over the issue's
ranges, runs every release (`--release-azimuth-deg all`: 0, 30, ..., 330) in both, and scores

- bare rim: T per release within 1 %;
- flared wall: the mean T within 5 % (where every release leaves in both);
- held: a release MuJoCo holds (still inside at the horizon) is held by the model too, and the
  other way round;
- regime: the category per release the same (held, or the dominant mode and how it left:
  compare.py's `category`).

The restitution `e` of a scene is given to MuJoCo as its contact's damping ratio: a normal
impact on a still plane with the bowl's contact settings is bisected for the ratio that returns
`e` (MuJoCo's critically damped contact already returns 0.13-0.15; e below 0.02 takes ratio 4).

Usage (in the venv compare.sh makes; `compare.sh sweep [ARGS]` does that and builds `bowl`):
  sweep.py BOWL_BINARY [--seed N] [--scenes N] [--jobs N] [--only I,J,..] [--dt S] [--out JSON]
           [--cache JSONL] [--cone] [--friction-tc S] [--impact-vn V] [--max-time-s S]
prints the scenes, a Markdown table per scene and the summary per target. --only reruns some
scenes (e.g. with a finer --dt to check the reference); --out keeps the raw results; --cache
keeps every finished MuJoCo release (keyed on all it depends on) and skips it when rerun.
"""
import argparse
import json
import math
import multiprocessing
import os
import random
import subprocess
import sys

import mujoco

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bowl_mujoco  # noqa: E402
import impact_mujoco  # noqa: E402
from compare import category  # noqa: E402

AZ = list(range(0, 360, 30))


def draw(seed, n):
    """n scenes over the issue's ranges: 30 % bare rims, 45 % flared walls, 25 % vertical walls;
    about one in eight on a rod offset. Lengths in m, angles in deg, speeds in rad/s."""
    rng = random.Random(seed)
    scenes = []
    for i in range(n):
        u = rng.random()
        kind = "bare" if u < 0.3 else ("flared" if u < 0.75 else "vertical")
        th = rng.uniform(60, 75) if rng.random() < 0.1 else rng.uniform(5, 60)
        rim = rng.uniform(0.075, 0.15)
        a = rng.uniform(0.002, 0.005)
        s = dict(
            i=i, kind=kind, th=th,
            w1=rng.choice((-1, 1)) * rng.uniform(0.5, 3.6),
            w2=rng.choice((-1, 1)) * rng.uniform(0.5, 3.6),
            rim=rim, ri=rng.uniform(0.2, 0.7) * rim, a=a,
            mu_r=rng.uniform(0.01, 0.05), mu_s=rng.uniform(0.2, 0.6), e=rng.uniform(0.0, 0.7),
            alpha=90.0, h=0.0, fillet=0.0,
            rod=rng.uniform(0.1, 0.3) if rng.random() < 0.125 else 0.0,
        )
        if kind == "flared":
            s["alpha"] = rng.uniform(30, 80)
            s["h"] = rng.uniform(0.005, 0.03)
        elif kind == "vertical":
            s["h"] = rng.uniform(0.01, 0.04)
        if kind != "bare" and rng.random() < 0.6:
            # The largest fillet the wall holds: F (1 - cos alpha) <= H.
            cap = s["h"] / (1 - math.cos(math.radians(s["alpha"])))
            s["fillet"] = min(rng.uniform(0.0, 0.008), cap)
        s["horizon"] = 3.0 if th < 20 else 2.0
        scenes.append(s)
    return scenes


def impact_e(dampratio, vz=0.2):
    """The restitution of a normal impact at vz on a still plane, the bowl's contact."""
    return impact_mujoco.mujoco_impact(0.0, vz, 0.0, 1.0, 0.0005, 0, dampratio)[2]


def dampratio_for(e):
    lo, hi = 0.02, 4.0  # e 0.95 .. 0.01
    if e <= impact_e(hi):
        return hi
    for _ in range(30):
        mid = math.sqrt(lo * hi)
        if impact_e(mid) > e:
            lo = mid
        else:
            hi = mid
    return math.sqrt(lo * hi)


def mujoco_release(job):
    s, beta, dr, dt, torque, ftc, ivn = job
    t, sh, touching = bowl_mujoco.run(
        s["w1"], s["w2"], math.radians(s["th"]), s["rim"], s["ri"], s["a"], s["mu_r"],
        s["mu_s"], math.radians(s["alpha"]), s["h"], s["rod"], s["horizon"],
        math.radians(beta), s["fillet"], dampratio=dr, dt=dt, torque=torque, friction_tc=ftc,
        impact_vn=ivn)
    total = sum(sh.values()) or 1.0
    how = "held" if t is None else ("contact" if touching else "flight")
    return [key(job), t, {k: v / total for k, v in sh.items()}, how]


def key(job):
    """What a release's MuJoCo answer depends on, for the cache (the friction's time constant
    and the impacts' normal speed only where they are set, so the runs without them keep their
    keys)."""
    s, beta, dr, dt, torque, ftc, ivn = job
    return json.dumps([s, beta, dr, dt, torque, bowl_mujoco.CONE_TORQUE if torque else
                       bowl_mujoco.CONE] + ([ftc] if ftc else [])
                      + ([{"impact_vn": ivn}] if ivn is not None else []), sort_keys=True)


def model(bowl, s):
    cmd = [bowl, "predict", "--model", "bowl", "--axes-angle-deg", s["th"],
           "--precession-rad-s", s["w1"], "--spin-rad-s", s["w2"], "--rim-radius-m", s["rim"],
           "--ri-m", s["ri"], "--particle-radius-m", s["a"], "--mu", s["mu_r"],
           "--sliding-mu", s["mu_s"], "--restitution", s["e"], "--wall-angle-deg", s["alpha"],
           "--wall-height-m", s["h"], "--fillet-radius-m", s["fillet"], "--rod-offset-m",
           s["rod"], "--max-time-s", s["horizon"], "--release-azimuth-deg", "all", "--json"]
    out = subprocess.run([str(x) for x in cmd], capture_output=True, text=True)
    if out.returncode != 0:
        return {"error": out.stderr.strip()}
    v = json.loads(out.stdout)
    return {"valid": v.get("valid", v.get("invalid_reason") is None),
            "invalid_reason": v.get("invalid_reason"),
            "rows": [(r["residence_time_s"], r["regime"],
                      "held" if not r["left"] else
                      ("flight" if r["left_in_flight"] else "contact"))
                     for r in v["per_release"]]}


def describe(s):
    shape = {"bare": "bare rim",
             "flared": f"flared {s['alpha']:.0f} deg, {1e3 * s['h']:.0f} mm",
             "vertical": f"vertical, {1e3 * s['h']:.0f} mm"}[s["kind"]]
    if s["fillet"] > 0:
        shape += f", fillet {1e3 * s['fillet']:.1f} mm"
    rod = f", rod {s['rod']:.2f} m" if s["rod"] else ""
    return (f"{s['i']}: {shape}; {s['th']:.1f} deg, w1 {s['w1']:+.2f} w2 {s['w2']:+.2f}{rod}; "
            f"R {1e3 * s['rim']:.0f} ri {1e3 * s['ri']:.0f} a {1e3 * s['a']:.1f} mm, "
            f"mu_r {s['mu_r']:.3f} mu_s {s['mu_s']:.2f} e {s['e']:.2f}")


def score(s, mj, us):
    """Per target: None (not applicable), or (passed, error or words)."""
    out = {}
    held_mj = [r[0] is None for r in mj]
    held_us = [r[0] is None for r in us]
    if any(held_mj) or any(held_us):
        same = held_mj == held_us
        out["held"] = (same, f"{sum(held_mj)}/{len(mj)} held, model {sum(held_us)}")
    both = [(m[0], u[0]) for m, u in zip(mj, us) if m[0] is not None and u[0] is not None]
    if s["kind"] == "bare" and both:
        errs = [u / m - 1 for m, u in both]
        worst = max(errs, key=abs)
        out["bare T"] = (abs(worst) <= 0.01 and len(both) == len(mj), worst)
    if s["kind"] != "bare" and not any(held_mj) and not any(held_us):
        err = sum(u for _, u in both) / sum(m for m, _ in both) - 1
        out["flared mean T" if s["kind"] == "flared" else "vertical mean T"] = (
            abs(err) <= 0.05, err)
    cm = [category(r) for r in mj]
    cu = [category(r) for r in us]
    same = sum(a == b for a, b in zip(cm, cu))
    out["regime"] = (same == len(cm), same, len(cm))
    return out


def main():
    p = argparse.ArgumentParser()
    p.add_argument("bowl")
    p.add_argument("--seed", type=int, default=30)
    p.add_argument("--scenes", type=int, default=40)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--only", default="")
    p.add_argument("--dt", type=float, default=bowl_mujoco.DT)
    p.add_argument("--out", default="")
    p.add_argument("--cone", action="store_true",
                   help="MuJoCo's own rolling friction (shares the friction cone) instead of "
                        "the rolling resistance as a torque while rolling")
    p.add_argument("--friction-tc", type=float, default=0.0,
                   help="the contact friction's own time constant, s (bowl_mujoco.run's "
                        "friction_tc; 1e-4 gives a sticking impact Routh's tangential impulse; "
                        "default: the normal's, 0.5 ms)")
    p.add_argument("--impact-vn", type=float, default=0.0,
                   help="the rolling resistance only while the contact's normal speed is at "
                        "most this, m/s, not in impacts (bowl_mujoco.run's impact_vn; the "
                        "model's impact has none; default: in every sticking contact)")
    p.add_argument("--max-time-s", type=float, default=0.0,
                   help="caps every scene's horizon (both MuJoCo and the model): for scenes "
                        "that clearly hold, where MuJoCo takes 2-3 s of run per release")
    p.add_argument("--cache", default="",
                   help="JSON lines of finished releases: read, skipped and appended to")
    args = p.parse_args()
    scenes = draw(args.seed, args.scenes)
    if args.only:
        keep = {int(x) for x in args.only.split(",")}
        scenes = [s for s in scenes if s["i"] in keep]
    if args.max_time_s > 0:
        for s in scenes:
            s["horizon"] = min(s["horizon"], args.max_time_s)
    ratios = {s["i"]: dampratio_for(s["e"]) for s in scenes}
    ivn = args.impact_vn if args.impact_vn > 0 else None
    jobs = [(s, b, ratios[s["i"]], args.dt, not args.cone, args.friction_tc or None, ivn)
            for s in scenes for b in AZ]
    done = {}
    if args.cache and os.path.exists(args.cache):
        with open(args.cache) as f:
            for line in f:
                k, t, sh, how = json.loads(line)
                done[k] = (t, sh, how)
    ours = {s["i"]: model(args.bowl, s) for s in scenes}

    def held(i):  # the model's held releases: the slow ones in MuJoCo, run last
        return sum(r[0] is None for r in ours[i].get("rows", []))

    todo = sorted((j for j in jobs if key(j) not in done), key=lambda j: held(j[0]["i"]))
    cache = open(args.cache, "a") if args.cache else None
    with multiprocessing.Pool(args.jobs) as pool:
        # Each release as it comes (a sweep takes most of an hour): to stderr and the cache.
        for n, row in enumerate(pool.imap_unordered(mujoco_release, todo, chunksize=1)):
            done[row[0]] = tuple(row[1:])
            if cache:
                cache.write(json.dumps(row) + "\n")
                cache.flush()
            print(f"{n + 1}/{len(todo)}: {row[1]} {row[3]}", file=sys.stderr, flush=True)
    mj = {s["i"]: [done[key(j)] for j in jobs if j[0] is s] for s in scenes}
    results = []
    for s in scenes:
        results.append(dict(scene=s, dampratio=ratios[s["i"]], mujoco=mj[s["i"]],
                            model=ours[s["i"]]))
    if args.out:
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)
    report(results)


def fmt_t(rows):
    return ", ".join("held" if r[0] is None else f"{r[0]:.4f}" for r in rows)


def report(results):
    tally = {}
    print("| scene | MuJoCo T per release (s) | model T per release (s) | scores |")
    print("| --- | --- | --- | --- |")
    for r in results:
        s, mj, us = r["scene"], r["mujoco"], r["model"]
        if "error" in us:
            print(f"| {describe(s)} | {fmt_t(mj)} | refused: {us['error']} | |")
            continue
        sc = score(s, mj, us["rows"])
        words = []
        for k, v in sc.items():
            t = tally.setdefault(k, dict(n=0, ok=0, worst=0.0, misses=[]))
            t["n"] += 1
            t["ok"] += v[0]
            if not v[0]:
                t["misses"].append(s["i"])
            if isinstance(v[1], float):
                t["worst"] = max(t["worst"], v[1], key=abs)
                words.append(f"{k} {100 * v[1]:+.2f} %{'' if v[0] else ' MISS'}")
            elif k == "regime":
                words.append(f"regime {v[1]}/{v[2]}{'' if v[0] else ' MISS'}")
            else:
                words.append(f"{k}: {v[1]}{'' if v[0] else ' MISS'}")
        if not us["valid"]:
            words.append(f"model not valid: {us['invalid_reason']}")
        print(f"| {describe(s)} | {fmt_t(mj)} | {fmt_t(us['rows'])} | {'; '.join(words)} |",
              flush=True)
    print()
    print("| target | scenes | pass | worst | misses (scene) |")
    print("| --- | --- | --- | --- | --- |")
    for k, t in tally.items():
        worst = f"{100 * t['worst']:+.2f} %" if t["worst"] else ""
        print(f"| {k} | {t['n']} | {t['ok']} | {worst} | {', '.join(map(str, t['misses']))} |")
    for r in results:
        s, mj, us = r["scene"], r["mujoco"], r["model"]
        if "error" in us:
            continue
        cm = [category(x) for x in mj]
        cu = [category(x) for x in us["rows"]]
        diff = [f"{b}: {x} / {y}" for b, x, y in zip(AZ, cm, cu) if x != y]
        if diff:
            print(f"scene {s['i']} regime MuJoCo / model: " + "; ".join(diff))


if __name__ == "__main__":
    main()
