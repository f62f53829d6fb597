#!/usr/bin/env bash
# The zoo's tracking runs (issue 24), after deblur's start-up: eval
# tracking on every zoo_blind design of tools/eval/seeds.toml, tumbling and
# slow-spin, 120 frames, deblur and ct-ndt, from the truth, on the first
# blind scenario seed. `spacepose eval tables` turns them into the table of
# docs/design/target-packages.md.
#   docs/results/measure-zoo-tracking.sh <spacepose binary> [designs...]
set -euo pipefail
bin=$(realpath "$1")
shift
cd "$(dirname "$0")/../.."
out=docs/results/zoo-tracking
seeds_file=tools/eval/seeds.toml
designs=${*:-"$(sed -n 's/^zoo_blind = \[\(.*\)\]/\1/p' "$seeds_file" | tr -d ,)"}
seed=$(sed -n 's/^blind = \[\([0-9]*\).*/\1/p' "$seeds_file")
mkdir -p "$out"
for n in $designs; do
  for sc in tumbling slow-spin; do
    "$bin" eval tracking --target "zoo:$n" --scenario "$sc" --frames 120 --seed "$seed" \
      --mode deblur,ct-ndt --json "$out/zoo-$n-$sc.json" > /dev/null 2>&1 \
      || echo "zoo:$n $sc failed"
  done
  echo "zoo:$n done"
done
docs/results/reduce-runs.py "$out"/*.json
