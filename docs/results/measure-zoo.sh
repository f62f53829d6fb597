#!/usr/bin/env bash
# The generated target zoo (issue 24 item 7), every sensor effect on:
#   docs/results/measure-zoo.sh <spacepose binary> <out dir> [designs...]
# A design is a seed N (the target zoo:N) or a built-in name; default: the
# zoo_blind seeds of tools/eval/seeds.toml, then deos and envisat. Per
# design N:
# - spacepose demo --target zoo:N --frames 40 --seed S (the whole suite,
#   acquired by template matching: no CNN exists for a generated target);
# - eval tracking, tumbling and slow-spin, 120 frames, every mode, from the
#   truth (the init chain is not in eval tracking yet);
# - eval tm on Mid-40 frames at 20 m, 10 random attitudes, one thread.
# S is the first blind scenario seed of tools/eval/seeds.toml. The JSON
# goes to <out dir>; docs/results/reduce-zoo.py prints the table.
set -euo pipefail
bin=$1
out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
seeds_file="$here/../../tools/eval/seeds.toml"
designs=${*:-"$(sed -n 's/^zoo_blind = \[\(.*\)\]/\1/p' "$seeds_file" | tr -d ,) deos envisat"}
seed=$(sed -n 's/^blind = \[\([0-9]*\).*/\1/p' "$seeds_file")
mkdir -p "$out"
for n in $designs; do
  case $n in
    *[!0-9]*) t=$n p="$out/$n" ;;
    *) t="zoo:$n" p="$out/zoo-$n" ;;
  esac
  "$bin" target show "$t" > "$p.txt"
  "$bin" demo --target "$t" --frames 40 --seed "$seed" \
    --json "$p-demo.json" > "$p-demo.log" 2>&1 || echo "$t demo failed"
  for sc in tumbling slow-spin; do
    "$bin" eval tracking --target "$t" --scenario "$sc" --frames 120 --seed "$seed" \
      --json "$p-$sc.json" > /dev/null 2>&1 || echo "$t $sc failed"
  done
  "$bin" eval tm --target "$t" --sensor mid40 --range 20 --count 10 --threads 1 \
    --seed "$seed" --json "$p-tm.json" > /dev/null 2>&1 || echo "$t tm failed"
  echo "$t done"
done
# Keep what the table needs: each frame's status and errors.
"$here/reduce-runs.py" "$out"/*-tumbling.json "$out"/*-slow-spin.json
python3 - "$out"/*-demo.json <<'PY'
import json, sys
for path in sys.argv[1:]:
    d = json.load(open(path))
    d.pop("fusions", None)
    d["series"] = [{k: f[k] for k in ("sequence", "status", "ang_err_deg", "pos_err_cm")}
                   for f in d["series"]]
    json.dump(d, open(path, "w"), separators=(",", ":"))
PY
"$here/reduce-zoo.py" "$out"
