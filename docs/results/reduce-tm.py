#!/usr/bin/env python3
"""The template-matching table of docs/design/target-packages.md from the
JSON reports of `spacepose eval tm` (docs/results/measure-tm-mid40.sh):
one row per target and range, the frames of every seed pooled."""
import json
import sys
from collections import defaultdict
from pathlib import Path


def main(paths):
    if not paths:
        sys.exit("usage: reduce-tm.py REPORT.json...")
    rows = defaultdict(list)
    for p in paths:
        d = json.loads(Path(p).read_text())
        rows[(Path(p).stem.split("-")[0], d["range_m"])].append(d)
    print("| target | range | seeds | frames | points (mean) | correct (< 3°) "
          "| accepted and correct | false accepts | false rejects | time mean / max (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    total = defaultdict(int)
    for (name, range_m), runs in sorted(rows.items()):
        n = sum(d["count"] for d in runs)
        pooled = lambda k: sum(d[k] * d["count"] for d in runs) / n
        fa = sum(d["false_accepts"] for d in runs)
        fr = sum(d["false_rejects"] for d in runs)
        t_max = max(d["time_ms"]["max"] for d in runs)
        t_mean = sum(d["time_ms"]["mean"] * d["count"] for d in runs) / n
        print(f"| {name} | {range_m:g} m | {len(runs)} | {n} | {pooled('mean_points'):.0f} "
              f"| {100 * pooled('success_rate'):.0f} % | {100 * pooled('accepted_success_rate'):.0f} % "
              f"| {fa} | {fr} | {t_mean:.0f} / {t_max:.0f} |")
        total["frames"] += n
        total["fa"] += fa
        total["correct"] += round(pooled("success_rate") * n)
        total["ok"] += round(pooled("accepted_success_rate") * n)
        total["slow"] += sum(1 for d in runs for f in d["frames"] if f["time_ms"] > 500)
    print(f"\n{len(rows)} rows, {total['frames']} frames: {total['correct']} correct, "
          f"{total['ok']} accepted and correct, {total['fa']} false accepts, "
          f"{total['slow']} attempts over 0.5 s.")


if __name__ == "__main__":
    main(sys.argv[1:])
