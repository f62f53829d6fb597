#!/usr/bin/env bash
# The committed Monte-Carlo reports: `eval tracking --report` over the blind
# seeds of tools/eval/seeds.toml, 120 frames per run, on deos, from the
# truth with zero rates (the start-up counts), and `acquired`: the deployed
# path from a no-truth start (`--init acquire`: init's CNN, then template
# matching, acquire on the frames and reacquire after a loss), and `clutter`
# and `clutter-acquired`: the same with the test facility's background in
# the frames (issue 25 item 6), and `mismatch` and `mismatch-acquired`:
# frames of the target as built, with its own motion within the scans,
# while the services keep the nominal package (issue 25 item 3).
# `spacepose eval tables` turns them into the table of docs/results.md.
#   docs/results/monte-carlo/measure.sh <spacepose binary>
# Each report takes 70-160 s on this project's 2-core machine (the twenty: about 40 minutes).
set -euo pipefail
bin=$(realpath "$1")
here=docs/results/monte-carlo
cd "$(dirname "$0")/../../.."
run() { # scenario, mode, name, [tracker config], [more arguments]
  local cfg=()
  [ -n "${4:-}" ] && cfg=(--tracker-config "$here/$4.toml")
  "$bin" eval tracking --scenario "$1" --frames 120 --mode "$2" "${cfg[@]}" \
    "${@:5}" --report "$here/deos-$1-$3.json" >/dev/null
}
for sc in tumbling slow-spin; do
  run $sc all defaults
  run $sc deblur no-start-up no-start-up
  run $sc deblur,ct-ndt acquired "" --init acquire
  run $sc deblur,ct-ndt clutter "" --clutter
  run $sc deblur,ct-ndt clutter-acquired "" --clutter --init acquire
  run $sc deblur,ct-ndt mismatch "" --mismatch
  run $sc deblur,ct-ndt mismatch-acquired "" --mismatch --init acquire
done
for sc in tumbling slow-spin; do
  for m in ndt deblur ct-ndt; do
    run $sc $m paper-$m paper-$m
  done
done
