#!/usr/bin/env bash
# Server CPU per request of GET /healthz and of a cached rolling request, for thirdbody
# builds and the bare floor (loadtest/bare/), interleaved so that they meet the same
# machine (issue 46: cached within 1.6x the bare server's CPU):
#
#   loadtest/floor.sh ROUNDS BINARY...
#   e.g. loadtest/floor.sh 4 loadtest/bare/target/release/thirdbody-bare target/release/thirdbody
#
# Each round starts each binary afresh, warms it, then runs wrk -t1 -c16 for 5 s on
# /healthz and 5 s with loadtest/post.lua. Prints one line per run: binary, then for each
# case its 2xx/s and the server's CPU (user + system, from /proc) per request in µs. The
# machine's speed moves by 40 % within an hour: compare builds within a round, and read
# loadtest/instructions.sh for a steady ruler.
set -euo pipefail
cd "$(dirname "$0")/.."
source loadtest/lib.sh
ROUNDS="$1"
shift
PORT=18081
BASE="http://127.0.0.1:$PORT"

# "RATE CPU_US" of a 5 s run of wrk with the arguments, against the server $1.
run() {
  local server="$1" before after rate
  shift
  before=$(ticks "$server")
  rate=$(wrk -t1 -c16 -d5s "$@" | awk '/^RESULT/ {print $2}')
  after=$(ticks "$server")
  awk -v t="$((after - before))" -v r="$rate" -v hz="$(getconf CLK_TCK)" \
    'BEGIN { printf "%d %.1f", r, (r > 0 ? 1e6 * t / hz / (5 * r) : 0) }'
}

for _ in $(seq "$ROUNDS"); do
  for binary in "$@"; do
    RUST_LOG=warn "$binary" serve --bind "127.0.0.1:$PORT" --database :memory: 2>/dev/null &
    server=$!
    wait_ready "$BASE"
    curl -sf -X POST -H 'content-type: application/json' -d '{}' "$BASE/v1/rolling" >/dev/null
    read -r health_rate health_cpu <<<"$(run "$server" -s loadtest/summary.lua "$BASE/healthz")"
    read -r cached_rate cached_cpu <<<"$(run "$server" -s loadtest/post.lua "$BASE/v1/rolling")"
    kill "$server"
    wait "$server" 2>/dev/null || true
    printf '%s healthz %s/s %s µs cached %s/s %s µs\n' \
      "$binary" "$health_rate" "$health_cpu" "$cached_rate" "$cached_cpu"
  done
done
