#!/usr/bin/env python3
"""The spin's reaction on a rod still held, against the rod's stiction (docs/control.md, "The spin
starts with the rod"): for every plant of each family file, `bowl sim trace` from rest to TARGET,
the spin's reaction `coupling J2 dw2/dt` from its true speed every 10 ms over the first 1.5 s
where the rod's true speed stayed zero, divided by the rod's stiction (its own and the
material's); and the rod's slowest true speed (below zero: it was dragged backwards).
usage: python3 docs/charts/spin_reaction.py BOWL TARGET FAMILY.toml [FAMILY.toml ...]"""
import subprocess, sys, tomllib

bowl, target = sys.argv[1], sys.argv[2]
rows, slowest = [], 0.0
for f in sys.argv[3:]:
    fam = tomllib.load(open(f, "rb"))
    for p in fam["plant"]:
        out = subprocess.run(
            [bowl, "sim", "trace", "--rig-file", f, "--name", p["name"], "--target-rad-s", target],
            capture_output=True, text=True, check=True).stdout.splitlines()[1:]
        t = [list(map(float, l.split(",")[:3])) for l in out if l[:1].isdigit()]
        t = [r for r in t if r[0] < 1.5]
        slowest = min([slowest] + [r[1] for r in t])
        held = [i for i in range(len(t) - 1) if t[i][1] == 0.0 and t[i + 1][1] == 0.0]
        accel = max(((t[i + 1][2] - t[i][2]) / (t[i + 1][0] - t[i][0]) for i in held), default=0.0)
        rod, spin = p["precession"], p["spin"]
        reaction = p["coupling"] * spin["inertia_kg_m2"] * accel
        hold = rod["stiction_nm"] + rod.get("load_step_nm", 0.0)
        rows.append((reaction / hold, f.split("/")[-1], p["name"]))
rows.sort(reverse=True)
print(f"{len(rows)} starts to {target} rad/s: reaction / rod stiction while held, largest "
      + ", ".join(f"{r:.2f} ({f} {n})" for r, f, n in rows[:3])
      + f"; the rod's slowest true speed {slowest:.4f} rad/s")
