#!/usr/bin/env python3
"""Per-axis misses (docs/control.md, "Transitions") of `bowl sim family --json` against issue 27's from-rest targets.
usage: python3 docs/charts/axis_misses.py BOWL FAMILY.toml [FAMILY.toml ...] [--from A] [--to B] [--current]"""
import json, subprocess, sys
args = sys.argv[1:]
bowl = args.pop(0)
frm, to, cur = "0", "1", False
fams = []
i = 0
while i < len(args):
    if args[i] == "--from": frm = args[i + 1]; i += 2
    elif args[i] == "--to": to = args[i + 1]; i += 2
    elif args[i] == "--current": cur = True; i += 1
    else: fams.append(args[i]); i += 1
for f in fams:
    cmd = [bowl, "sim", "family", "--rig-file", f, "--from-rad-s", frm, "--target-rad-s", to, "--json"]
    if cur: cmd.append("--current-sense")
    d = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
    n = os5 = os10 = s3 = 0
    worst = 0.0
    miss = []
    ff = 0
    for p in d["plants"]:
        ff += bool(p.get("false_fault"))
        for ax, a in (p.get("axes") or {}).items():
            n += 1
            o = a.get("overshoot_pct") or 0.0
            s = a.get("settling_2pct_s")
            worst = max(worst, o)
            os5 += o <= 5; os10 += o <= 10
            ok3 = s is not None and s <= 3.0
            s3 += ok3
            if o > 10 or not ok3:
                miss.append(f"{p['name']}:{ax[:4]} os {o:.1f} s2 {s if s is None else round(s,2)}")
    print(f"{f}: {frm}->{to} axes {n} false {ff} os<=5 {100*os5/n:.1f}% os<=10 {100*os10/n:.1f}% worst {worst:.1f}% 2%<=3s {100*s3/n:.1f}%")
    for m in miss: print("   ", m)
