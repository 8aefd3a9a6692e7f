#!/usr/bin/env bash
# Uncached rolling throughput as a share of cached, at 16 connections (issue 12's target: at
# least 50 %), for one or more builds, interleaved so that they meet the same machine:
#
#   loadtest/ratio.sh ROUNDS [BINARY...]      (default: one build, target/release/thirdbody)
#
# Each round starts each binary afresh, warms the cached input, then runs wrk -t1 -c16 for 5 s
# with loadtest/post.lua (one input, cached) and 5 s with loadtest/distinct.lua (every input
# new, solved). Prints one line per run: binary, cached 2xx/s, uncached 2xx/s, the ratio in %.
# A single pair is noisy on a shared 2-core machine (the ratio moved by ±8 points between
# runs of one build): compare builds over several rounds.
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS="${1:-4}"
shift || true
BINARIES=("$@")
if [ ${#BINARIES[@]} -eq 0 ]; then
  cargo build --release --locked -q
  BINARIES=(target/release/thirdbody)
fi
PORT=18080
BASE="http://127.0.0.1:$PORT"

rate() {
  wrk -t1 -c16 -d5s "$@" | awk '/^RESULT/ {print $2}'
}

for round in $(seq "$ROUNDS"); do
  for binary in "${BINARIES[@]}"; do
    RUST_LOG=warn "$binary" serve --bind "127.0.0.1:$PORT" 2>/dev/null &
    server=$!
    for _ in $(seq 100); do
      curl -sf "$BASE/healthz" >/dev/null && break
      sleep 0.1
    done
    curl -sf -X POST -H 'content-type: application/json' -d '{}' "$BASE/v1/rolling" >/dev/null
    cached=$(rate -s loadtest/post.lua "$BASE/v1/rolling")
    uncached=$(rate -s loadtest/distinct.lua "$BASE/v1/rolling" -- "$((round * 1000000000))")
    kill "$server"
    wait "$server" 2>/dev/null || true
    awk -v b="$binary" -v c="$cached" -v u="$uncached" \
      'BEGIN { printf "%s %d %d %.1f %%\n", b, c, u, 100 * u / c }'
  done
done
