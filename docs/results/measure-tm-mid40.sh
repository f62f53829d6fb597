#!/usr/bin/env bash
# Template matching on the suite's sensor (docs/design/target-packages.md):
# `eval tm --sensor mid40` (Livox Mid-40 frames, every sensor effect on,
# the init service's 2 cm voxels), one thread, 10 random attitudes at a
# fixed range per row and seed, the library's defaults, on the first three
# blind seeds of tools/eval/seeds.toml (or the seeds given after the out dir).
#   docs/results/measure-tm-mid40.sh <spacepose binary> <out dir> [seed...]
# docs/results/reduce-tm.py <out dir>/*.json prints the note's table.
# Run it alone on the machine: the times are wall times of one core.
set -euo pipefail
bin=$1
out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
meshes="$here/../../tests/fixtures/meshes"
seeds=${*:-$(sed -n 's/^blind = \[\(.*\)\]/\1/p' "$here/../../tools/eval/seeds.toml" | tr -d , | cut -d' ' -f1-3)}
mkdir -p "$out"
for row in deos:1:5 deos:1:10 deos:1:30 envisat:1:10 envisat:1:30 envisat:1:50 \
  "$meshes/telescope.stl:0.001:10" "$meshes/telescope.stl:0.001:40" \
  "$meshes/relay.stl:1:30" "$meshes/relay.stl:1:50" "$meshes/comsat.stl:1:20" \
  "$meshes/probe.stl:1:5" "$meshes/probe.stl:1:15"; do
  IFS=: read -r spec scale range <<< "$row"
  name=$(basename "$spec" .stl)
  for seed in $seeds; do
    "$bin" eval tm --target "$spec" --scale "$scale" --sensor mid40 --range "$range" \
      --count 10 --threads 1 --seed "$seed" --json "$out/$name-$range-$seed.json" > /dev/null
  done
done
"$here/reduce-tm.py" "$out"/*.json
