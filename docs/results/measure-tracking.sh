#!/usr/bin/env bash
# The committed tracking runs: eval tracking, every mode, on the blind
# seeds of tools/eval/seeds.toml.
#   docs/results/measure-tracking.sh <spacepose binary> <out dir>
# tracking-blind/ holds the runs of the current CLI; frame-path-before/
# those of the CLI built at 034f1c4, before the one frame path
# (docs/design/frame-path.md). `spacepose eval tables` turns them into the
# tables of the README and docs/.
# The first 300 frames of tumbling and of slow-spin (the whole scenarios
# are ~1,400 frames, 5 minutes a seed for the four modes on one core) on
# the first 5 blind seeds.
set -euo pipefail
bin=$1
out=$2
mkdir -p "$out"
seeds=$(sed -n 's/^blind = \[\(.*\)\]/\1/p' "$(dirname "$0")/../../tools/eval/seeds.toml" | tr -d ,)
for s in $(echo $seeds | cut -d' ' -f1-5); do
  for scenario in tumbling slow-spin; do
    "$bin" eval tracking --scenario $scenario --frames 300 --seed "$s" \
      --json "$out/$scenario-$s.json" >/dev/null
  done
done
# Keep the summaries and each frame's status and errors.
"$(dirname "$0")/reduce-runs.py" "$out"/*.json
