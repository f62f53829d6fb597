#!/usr/bin/env bash
# The committed runs on other targets (docs/design/target-packages.md):
# eval tracking, every mode, the first 120 frames of tumbling (the 15 m
# inspection), on the first 5 blind seeds of tools/eval/seeds.toml, for
# the built-in targets and the test meshes of tests/fixtures/meshes (each
# prepared into a package on first use).
#   docs/results/measure-targets.sh <spacepose binary> <out dir>
# `spacepose eval tables` turns them into the note's table.
set -euo pipefail
bin=$1
out=$2
here=$(cd "$(dirname "$0")" && pwd)
meshes="$here/../../tests/fixtures/meshes"
mkdir -p "$out"
seeds=$(sed -n 's/^blind = \[\(.*\)\]/\1/p' "$here/../../tools/eval/seeds.toml" | tr -d ,)
targets="deos:1 envisat:1 $meshes/telescope.stl:0.001 $meshes/relay.stl:1 $meshes/comsat.stl:1 $meshes/probe.stl:1"
for t in $targets; do
  spec=${t%:*}
  scale=${t##*:}
  name=$(basename "$spec" .stl)
  for s in $(echo $seeds | cut -d' ' -f1-5); do
    "$bin" eval tracking --target "$spec" --scale "$scale" --scenario tumbling \
      --frames 120 --seed "$s" --json "$out/$name-tumbling-$s.json" >/dev/null
  done
done
"$here/reduce-runs.py" "$out"/*.json
