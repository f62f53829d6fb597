#!/usr/bin/env python3
"""The target-zoo table of docs/design/target-packages.md from the JSON of
docs/results/measure-zoo.sh: one row per generated design, then how many
designs meet each goal of issue 24.

  docs/results/reduce-zoo.py DIR

A tracking frame is "silent" when it is published `tracking` more than 10°
or 50 cm off. "acq" is the first demo frame with a pose (the first accepted
acquisition, caught up by the tracker)."""
import json
import re
import sys
from pathlib import Path

MODES = ("deblur", "ct-ndt")


def silent(series):
    return sum(1 for f in series if f["status"] == "tracking"
               and (f["ang_err_deg"] > 10 or f["pos_err_cm"] > 50))


def tracking(path):
    """Max angle after warm-up per mode, silent frames, and whether every
    frame was held (none lost)."""
    if not path.exists():
        return None
    d = json.loads(path.read_text())
    out = {}
    for m in MODES:
        r = d["modes"][m]
        out[m] = (r["ang_err_deg_converged"]["max"], silent(r["series"]),
                  r["lost_frames"], r["time_ms_median"])
    return out


def demo(path):
    if not path.exists():
        return None
    d = json.loads(path.read_text())
    first = next((k for k, f in enumerate(d["series"]) if f["status"] != "lost"), None)
    return (first, d["missed_poses"], d["ang_err_deg_converged"]["max"], silent(d["series"]))


def tm(path):
    if not path.exists():
        return None
    d = json.loads(path.read_text())
    return (d["success_rate"], d["accepted_success_rate"], d["false_accepts"],
            d["time_ms"]["max"])


def design(txt):
    text = txt.read_text()
    radius = float(re.search(r"bounding radius ([0-9.]+) m", text).group(1))
    m = re.search(r"generator v\d+, ([^)]*)\)", text)
    intent = m.group(1).replace(" symmetric about x", "") if m else "-"
    group = re.search(r"symmetry \(\w+\): (\d+) rotation", text).group(1)
    return radius, intent, group


def fmt(x, spec=".2f"):
    return "-" if x is None else format(x, spec)


def main(argv):
    if len(argv) != 1:
        sys.exit("usage: reduce-zoo.py DIR")
    root = Path(argv[0])
    stems = [p.stem for p in root.glob("*.txt")]
    names = sorted(s for s in stems if s.startswith("zoo-"))
    names.sort(key=lambda s: int(s.split("-")[1]))
    builtins = sorted(s for s in stems if not s.startswith("zoo-"))
    print("| design | intent | R (m) | group | tumbling max* deblur / ct-ndt (°) "
          "| slow-spin max* deblur / ct-ndt (°) | silent | demo acq frame / missed / max* (°) "
          "| TM 20 m correct / accepted-correct / false accepts / max ms |")
    print("|---|---|---|---|---|---|---|---|---|")
    goals = {"tracking": 0, "demo": 0, "tm": 0, "tm_fa": 0, "tm_slow": 0, "silent": 0}
    for n in names + builtins:
        stem = root / n
        radius, intent, group = design(Path(f"{stem}.txt"))
        runs = [tracking(Path(f"{stem}-{sc}.json")) for sc in ("tumbling", "slow-spin")]
        dm = demo(Path(f"{stem}-demo.json"))
        t = tm(Path(f"{stem}-tm.json"))
        quiet = sum(r[m][1] for r in runs if r for m in MODES) + (dm[3] if dm else 0)
        held = all(r and all(r[m][0] <= 3 and r[m][2] == 0 for m in MODES) for r in runs)
        if n not in builtins:
            goals["tracking"] += held
            goals["silent"] += quiet
            goals["demo"] += bool(dm and dm[0] is not None and dm[0] < 5 and dm[1] == 0
                                  and dm[2] <= 3)
            if t:
                goals["tm"] += t[0] >= 0.85
                goals["tm_fa"] += t[2]
                goals["tm_slow"] += t[3] > 500
        cell = lambda r: "-" if not r else " / ".join(fmt(r[m][0]) for m in MODES)
        d = "-" if not dm else f"{fmt(dm[0], 'd')} / {dm[1]} / {fmt(dm[2])}"
        tmc = "-" if not t else (f"{100 * t[0]:.0f} % / {100 * t[1]:.0f} % / {t[2]} "
                                 f"/ {t[3]:.0f}")
        if n in builtins:
            print(f"| {n} (built-in) | {intent} | {radius:.2f} | {group} | {cell(runs[0])} "
                  f"| {cell(runs[1])} | {quiet} | {d} | {tmc} |")
            continue
        print(f"| {n.replace('zoo-', 'zoo:')} | {intent} | {radius:.2f} | {group} | {cell(runs[0])} "
              f"| {cell(runs[1])} | {quiet} | {d} | {tmc} |")
    k = len(names)
    print(f"\n{k} generated designs (the built-ins are not counted). Tracking held with max* <= 3° (both modes, both scenarios): "
          f"{goals['tracking']}/{k}. Demo (pose by frame 4, no missed pose, max* <= 3°): "
          f"{goals['demo']}/{k}. Template matching >= 85 % correct at 20 m: "
          f"{goals['tm']}/{k}, {goals['tm_fa']} false accepts, {goals['tm_slow']} designs "
          f"with an attempt over 0.5 s. Silent frames (tracking, > 10° or 50 cm off): "
          f"{goals['silent']}.")


if __name__ == "__main__":
    main(sys.argv[1:])
