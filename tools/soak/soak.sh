#!/usr/bin/env bash
# Soak run of the demo suite: N frames at R Hz through the real service
# processes (`spacepose demo`), sampling the resident memory (VmRSS) of every
# service process every few seconds. Writes, in OUT_DIR:
#   rss.csv      t_s,instance,pid,rss_kb,anon_kb (one row per process and
#                sample; anon = RssAnon, the private heap without the
#                iceoryx2 shared-memory pages that VmRSS also counts)
#   summary.json per instance: rss and anon at the first sample after the
#                warm-up, at the last sample, their growth, and the peak rss
#   demo.json    the demo's own summary (poses, errors, latencies)
#   demo.log     the demo's console output
#
# Default: 6000 frames at 10 Hz = 10 minutes. Not part of any test suite
# (it takes 10 minutes); run it by hand:
#   tools/soak/soak.sh                      # 6000 frames, 10 Hz
#   FRAMES=600 RATE_HZ=10 tools/soak/soak.sh /tmp/soak-short
# Needs the release binaries (cargo build --release -p spacepose
# -p spacepose-lidar-sim -p spacepose-ingest -p spacepose-tracker
# -p spacepose-filter -p spacepose-telemetry) in $BIN_DIR
# (default $CARGO_TARGET_DIR/release or target/release) and jq.
set -euo pipefail

FRAMES=${FRAMES:-6000}
RATE_HZ=${RATE_HZ:-10}
SAMPLE_S=${SAMPLE_S:-5}
WARMUP_S=${WARMUP_S:-30}
OUT_DIR=${1:-/tmp/spacepose-soak}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BIN_DIR=${BIN_DIR:-${CARGO_TARGET_DIR:-$ROOT/target}/release}
PREFIX=${PREFIX:-soak$$}
PORT=${PORT:-$((20000 + $$ % 20000))}

mkdir -p "$OUT_DIR"
DESC="$OUT_DIR/soak.toml"
# The demo descriptor at the soak rate; frames come from --frames.
sed -e "s/^rate_hz = .*/rate_hz = $RATE_HZ/" "$ROOT/deploy/demo.toml" >"$DESC"
STATE="${TMPDIR:-/tmp}/spacepose/$PREFIX/state.json"

echo "soak: $FRAMES frames at $RATE_HZ Hz, prefix $PREFIX, port $PORT, output $OUT_DIR"
cd "$ROOT"
"$BIN_DIR/spacepose" demo --deploy "$DESC" --frames "$FRAMES" --prefix "$PREFIX" \
    --listen "tcp/127.0.0.1:$PORT" --json "$OUT_DIR/demo.json" >"$OUT_DIR/demo.log" 2>&1 &
DEMO=$!
trap 'kill "$DEMO" 2>/dev/null || true' EXIT

echo "t_s,instance,pid,rss_kb,anon_kb" >"$OUT_DIR/rss.csv"
START=$(date +%s)
while kill -0 "$DEMO" 2>/dev/null; do
    if [[ -f "$STATE" ]]; then
        now=$(($(date +%s) - START))
        jq -r '.instances[] | "\(.name) \(.pid)"' "$STATE" | while read -r name pid; do
            mem=$(awk '/^VmRSS:/ {r = $2} /^RssAnon:/ {a = $2} END {if (r != "") print r "," a}' \
                "/proc/$pid/status" 2>/dev/null || true)
            [[ -n "$mem" ]] && echo "$now,$name,$pid,$mem" >>"$OUT_DIR/rss.csv"
        done
    fi
    sleep "$SAMPLE_S"
done
wait "$DEMO" && status=0 || status=$?
trap - EXIT

# First sample at or after the warm-up, last sample, peak: per instance.
awk -F, -v warm="$WARMUP_S" 'NR > 1 {
        if (!($2 in first) && $1 >= warm) { first[$2] = $4; afirst[$2] = $5; t0[$2] = $1 }
        last[$2] = $4; alast[$2] = $5; t1[$2] = $1
        if ($4 > peak[$2]) peak[$2] = $4
    }
    END {
        printf "{\n"; n = 0
        for (k in last) {
            if (!(k in first)) { first[k] = last[k]; afirst[k] = alast[k]; t0[k] = t1[k] }
            printf "%s  \"%s\": {\"start_t_s\": %d, \"start_rss_kb\": %d, \"start_anon_kb\": %d, \"end_t_s\": %d, \"end_rss_kb\": %d, \"end_anon_kb\": %d, \"rss_growth_kb\": %d, \"anon_growth_kb\": %d, \"peak_rss_kb\": %d}",
                (n++ ? ",\n" : ""), k, t0[k], first[k], afirst[k], t1[k], last[k], alast[k], last[k] - first[k], alast[k] - afirst[k], peak[k]
        }
        printf "\n}\n"
    }' "$OUT_DIR/rss.csv" >"$OUT_DIR/summary.json"
echo "soak: demo exited with status $status"
cat "$OUT_DIR/summary.json"
exit "$status"
