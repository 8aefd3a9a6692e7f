#!/usr/bin/env bash
# Load test of `thirdbody serve` on loopback, in one run: requests/s and p50/p99 latency for
# (a) GET /healthz, (b) a cached rolling job, (c) uncached rolling jobs (every input
# distinct), at 1, 16 and 64 connections. Prints a Markdown table for BENCHMARKS.md.
#
#   loadtest/run.sh [SECONDS_PER_CASE]     (default 10)
#
# Installs wrk (Debian) if it is missing. Not part of CI. The server runs with its defaults
# (pool size = cores) and RUST_LOG=warn, so that per-request log lines are not measured.
set -euo pipefail
cd "$(dirname "$0")/.."
source loadtest/lib.sh
DURATION="${1:-10}"

if ! command -v wrk >/dev/null; then
  apt-get update -q
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q wrk
fi
cargo build --release --locked -q

PORT=18080
BASE="http://127.0.0.1:$PORT"
RUST_LOG=warn target/release/thirdbody serve --bind "127.0.0.1:$PORT" 2>/tmp/thirdbody-loadtest.log &
SERVER=$!
trap 'kill "$SERVER" 2>/dev/null || true' EXIT
wait_ready "$BASE"

# One case: prints `| name | connections | ok req/s | all req/s | p50 | p99 | non-2xx |`.
measure() {
  local name="$1" connections="$2"
  shift 2
  local result
  result=$(wrk -t1 -c"$connections" -d"${DURATION}s" --latency "$@" | grep '^RESULT')
  read -r _ ok all p50 p99 non2xx <<<"$result"
  printf '| %s | %d | %s | %s | %s µs | %s µs | %s |\n' \
    "$name" "$connections" "$ok" "$all" "$p50" "$p99" "$non2xx"
}

echo "| case | connections | 2xx req/s | all req/s | p50 | p99 | non-2xx responses |"
echo "|---|---|---|---|---|---|---|"
for c in 1 16 64; do
  measure "(a) GET /healthz" "$c" -s loadtest/summary.lua "$BASE/healthz"
done
curl -sf -X POST -H 'content-type: application/json' -d '{}' "$BASE/v1/rolling" >/dev/null
for c in 1 16 64; do
  measure "(b) cached rolling" "$c" -s loadtest/post.lua "$BASE/v1/rolling"
done
for c in 1 16 64; do
  measure "(c) uncached rolling" "$c" -s loadtest/distinct.lua "$BASE/v1/rolling" -- "$((c * 1000000000))"
done
