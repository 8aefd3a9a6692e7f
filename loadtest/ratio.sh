#!/usr/bin/env bash
# Uncached rolling throughput as a share of cached, at 16 connections (issue 12's target: at
# least 50 %), for one or more builds, interleaved so that they meet the same machine:
#
#   loadtest/ratio.sh ROUNDS [BINARY...]      (default: one build, target/release/thirdbody)
#
# Each round starts each binary afresh, warms the cached input, then runs wrk -t1 -c16 for 5 s
# with loadtest/post.lua (one input, cached) and 5 s with loadtest/distinct.lua (every input
# new, solved). Prints one line per run: binary, cached 2xx/s, uncached 2xx/s, the ratio in %,
# and the server's CPU time per request (user + system, from /proc) in each run, in µs.
# A single pair is noisy on a shared 2-core machine (the ratio moved by ±8 points between
# runs of one build, and by ±10 on a busy day): compare builds over several rounds, and
# read the CPU per request, which the load generator sharing the cores moves less.
set -euo pipefail
cd "$(dirname "$0")/.."
source loadtest/lib.sh
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

# µs of CPU per request: ticks $1 over a 5 s run at $2 requests/s ("n/a" if none answered).
per_request() {
  awk -v t="$1" -v r="$2" -v hz="$(getconf CLK_TCK)" \
    'BEGIN { if (r > 0) printf "%.1f", 1e6 * t / hz / (5 * r); else printf "n/a" }'
}

for round in $(seq "$ROUNDS"); do
  for binary in "${BINARIES[@]}"; do
    RUST_LOG=warn "$binary" serve --bind "127.0.0.1:$PORT" 2>/dev/null &
    server=$!
    wait_ready "$BASE"
    curl -sf -X POST -H 'content-type: application/json' -d '{}' "$BASE/v1/rolling" >/dev/null
    start=$(ticks "$server")
    cached=$(rate -s loadtest/post.lua "$BASE/v1/rolling")
    middle=$(ticks "$server")
    uncached=$(rate -s loadtest/distinct.lua "$BASE/v1/rolling" -- "$((round * 1000000000))")
    end=$(ticks "$server")
    kill "$server"
    wait "$server" 2>/dev/null || true
    cached_cpu=$(per_request "$((middle - start))" "$cached")
    uncached_cpu=$(per_request "$((end - middle))" "$uncached")
    awk -v b="$binary" -v c="$cached" -v u="$uncached" -v cc="$cached_cpu" -v uc="$uncached_cpu" \
      'BEGIN { printf "%s %d %d %.1f %% cpu %s %s us\n", b, c, u, (c > 0 ? 100 * u / c : 0), cc, uc }'
  done
done
