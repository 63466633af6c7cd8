"""scipy's solve_ivp (RK45, DOP853, terminal event at r = R) against our integrators.

Usage: compare.py OURS.csv OUT_STEM
  OURS.csv  the CSV of `bowl chart work-precision --csv-only` (scenes, reference T, our runs)
  OUT_STEM  writes OUT_STEM.csv (every scipy run and our matching runs) and OUT_STEM.md (report)

Error is measured exactly as for our methods: |T - T_ref| / T_ref against the 256-bit reference T
of the same scene that `bowl` wrote into OURS.csv. The fair comparison of methods is achieved error
against right-hand-side evaluations; time per call mostly measures the Python interpreter's
overhead per RHS call, and is reported for what a user would actually wait.
"""

import csv
import math
import platform
import sys
import timeit

import numpy as np
import scipy
from scipy.integrate import solve_ivp

TOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
METHODS = ["RK45", "DOP853"]


def read_ours(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    scenes = {}
    for r in rows:
        if r["family"] == "closed" and r["precision"] == "f64":
            scenes[(r["scene"], r["model"])] = r
    return rows, scenes


def solve(p, model, method, tol):
    w, mu, g, k2 = float(p["w_rad_s"]), float(p["mu"]), float(p["g"]), float(p["k2"])
    ri, rim = float(p["ri_m"]), float(p["R_m"])
    cor = 2.0 * mu * w if model == "coriolis" else 0.0

    def rhs(t, y):
        r, v = y
        return [v, k2 * (r * w * w - mu * g - cor * v)]

    def hit_rim(t, y):
        return y[0] - rim

    hit_rim.terminal = True
    hit_rim.direction = 1
    sol = solve_ivp(rhs, (0.0, 1e3 / w), [ri, 0.0], method=method, rtol=tol,
                    atol=tol * rim, events=hit_rim)
    t = sol.t_events[0][0] if len(sol.t_events[0]) else math.inf
    return t, sol.nfev, (rhs, hit_rim, w, ri, rim, tol)


def time_call(fn):
    # Median of 5 repeats, each long enough (>= 20 ms) to dwarf the timer.
    t = timeit.Timer(fn)
    n, _ = t.autorange()
    n = max(1, n // 10)
    runs = sorted(t.repeat(repeat=5, number=n))
    return runs[2] / n * 1e9


def loglog_interp(x, xs, ys):
    """y at x on the piecewise log-log line through (xs, ys); None outside the range."""
    pts = sorted((a, b) for a, b in zip(xs, ys) if a > 0 and b > 0)
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        if min(x0, x1) <= x <= max(x0, x1) and x0 != x1:
            f = (math.log(x) - math.log(x0)) / (math.log(x1) - math.log(x0))
            return math.exp(math.log(y0) + f * (math.log(y1) - math.log(y0)))
    return None


def geo_mean(v):
    v = [x for x in v if x and x > 0 and math.isfinite(x)]
    return math.exp(sum(math.log(x) for x in v) / len(v)) if v else None


def fmt(x, spec=".3g"):
    return "n/a" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def main():
    ours_csv, stem = sys.argv[1], sys.argv[2]
    rows, scenes = read_ours(ours_csv)
    out_rows = []
    for (scene, model), p in sorted(scenes.items()):
        t_ref = float(p["ref_residence_time_s"])
        for method in METHODS:
            for tol in TOLS:
                t, nfev, _ = solve(p, model, method, tol)
                err = abs(t - t_ref) / t_ref if math.isfinite(t) else math.inf
                ns = time_call(lambda: solve(p, model, method, tol))
                out_rows.append(dict(scene=scene, model=model, who="scipy", method=method,
                                     setting=f"rtol={tol:g}", rel_error=err, rhs_evals=nfev,
                                     ns_per_call=ns))
    # Our f64 integrators from the same CSV.
    for r in rows:
        if r["precision"] == "f64" and r["family"] in ("dp54", "rk4") and r["rel_error"]:
            out_rows.append(dict(scene=r["scene"], model=r["model"], who="ours",
                                 method=r["family"], setting=r["setting"],
                                 rel_error=float(r["rel_error"]),
                                 rhs_evals=int(r["rhs_evals"]) if r["rhs_evals"] else None,
                                 ns_per_call=float(r["host_ns_per_call"])))
    with open(stem + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(out_rows[0].keys()))
        w.writeheader()
        for r in out_rows:
            w.writerow({k: (f"{v:.6e}" if isinstance(v, float) else v) for k, v in r.items()})

    # Ratios at equal achieved error: for each scipy run, our cost at the same error by log-log
    # interpolation along our tolerance (DP5(4)) or step (RK4) sweep.
    lines = []
    summary = []
    for (scene, model) in sorted(scenes):
        sel = [r for r in out_rows if r["scene"] == scene and r["model"] == model]
        for ours in ("dp54", "rk4"):
            o = [r for r in sel if r["who"] == "ours" and r["method"] == ours]
            if len(o) < 2:
                continue
            oe = [r["rel_error"] for r in o]
            for method in METHODS:
                ev_ratios, t_ratios = [], []
                for s in (r for r in sel if r["who"] == "scipy" and r["method"] == method):
                    e = s["rel_error"]
                    our_ev = loglog_interp(e, oe, [r["rhs_evals"] for r in o])
                    our_ns = loglog_interp(e, oe, [r["ns_per_call"] for r in o])
                    if our_ev:
                        ev_ratios.append(s["rhs_evals"] / our_ev)
                    if our_ns:
                        t_ratios.append(s["ns_per_call"] / our_ns)
                summary.append((scene, model, method, ours, geo_mean(ev_ratios),
                                len(ev_ratios), geo_mean(t_ratios)))

    md = []
    md.append("# Side by side: scipy `solve_ivp` against our integrators\n")
    md.append("Generated by `tests/scipy/compare.sh` (do not edit by hand). "
              f"Python {platform.python_version()}, numpy {np.__version__}, "
              f"scipy {scipy.__version__}, on {platform.machine()}.\n")
    md.append("Every run integrates the same ODE (paper Eq. 5 flat, Eq. 9 with the Coriolis "
              "term) from r = ri, r' = 0 and stops at the rim with an event: scipy with a "
              "terminal event function (root found on its dense output), ours with "
              "dense-output event location. The error is |T - T_ref| / T_ref against the "
              "256-bit reference written by `bowl chart work-precision` for the same scene. "
              "scipy runs with rtol = tol, atol = tol * R.\n")
    md.append("**How to read the ratios.** *RHS evaluations* is the fair comparison of the "
              "methods: it counts the work each method needs for the same achieved error, "
              "independent of language. *Time* is what a user waits for one residence time: "
              "for scipy it is dominated by the Python interpreter (each RHS call, event call "
              "and step costs microseconds of interpreter overhead), so it says little about "
              "the method and much about calling Python per step.\n")
    md.append("## Ratios at equal achieved error (geometric mean over scipy's tolerance sweep)\n")
    md.append("| scene | model | scipy method | ours | scipy RHS evals / ours | points | "
              "scipy time / ours |")
    md.append("|---|---|---|---|---|---|---|")
    for scene, model, method, ours, ev, n, tr in summary:
        md.append(f"| {scene} | {model} | {method} | {ours} | {fmt(ev)} | {n} | {fmt(tr)} |")
    if not summary:
        md.append("| (our integrator rows were missing from the CSV) | | | | | | |")
    md.append("\nA ratio above 1 means scipy needed more. Points where scipy's error lies outside "
              "the range our sweep reached are left out (`points` counts the rest).\n")
    md.append("## Every run\n")
    md.append("| scene | model | who | method | setting | rel. error | RHS evals | ns per call |")
    md.append("|---|---|---|---|---|---|---|---|")
    for r in out_rows:
        md.append(f"| {r['scene']} | {r['model']} | {r['who']} | {r['method']} | "
                  f"{r['setting']} | {fmt(r['rel_error'], '.2e')} | {r['rhs_evals']} | "
                  f"{fmt(r['ns_per_call'], '.4g')} |")
    with open(stem + ".md", "w") as f:
        f.write("\n".join(md) + "\n")
    for line in md[5:5 + 3 + len(summary)]:
        print(line)
    print(f"wrote {stem}.md and {stem}.csv")


if __name__ == "__main__":
    main()
