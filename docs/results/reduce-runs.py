#!/usr/bin/env python3
"""Reduces `eval tracking --json` runs in place to what the tables need:
the summaries and, of each frame, its status and errors (the full series
are ~1 MB a run; rerun with --json to see them).
    docs/results/reduce-runs.py RUN.json...
"""
import json
import sys

KEEP = ("frame", "status", "ang_err_deg", "pos_err_cm")

def rnd(v):
    return round(v, 5) if isinstance(v, float) else v

for path in sys.argv[1:]:
    run = json.load(open(path))
    for mode in run["modes"].values():
        mode["series"] = [{k: rnd(x[k]) for k in KEEP} for x in mode["series"]]
    json.dump(run, open(path, "w"), separators=(",", ":"))
