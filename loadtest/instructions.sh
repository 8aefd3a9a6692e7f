#!/usr/bin/env bash
# Instructions a server executes per request (a rolling one, cached or uncached, or GET
# /healthz), counted by callgrind: a ruler that the machine's load does not move (this VM's
# speed changes by 40 % within an hour, and it has no hardware counters). Cache misses and
# memory traffic are not counted: read it next to loadtest/ratio.sh, not instead of it.
#
#   loadtest/instructions.sh cached|uncached|healthz N BINARY...
#
# A BINARY is run as `BINARY serve --bind ADDRESS --database :memory:` (loadtest/bare/, the
# floor without thirdbody's layers, takes the same arguments).
#
# Each binary serves, under valgrind, 300 requests to warm up and then N more, and the same
# 300 alone in a second run; the difference over N is one request's instructions (every
# thread, the HTTP stack included). Logging is at warn, as in ratio.sh. Under valgrind the
# CPU has no SHA extensions: SHA-256 of an uncached input's key counts ~17,000 instructions
# that the real CPU spends ~1,000 on.
set -euo pipefail
cd "$(dirname "$0")/.."
source loadtest/lib.sh
MODE="$1"
N="$2"
shift 2

# Sends COUNT requests on one connection: rolling jobs (the default one, or each with a load
# of its own, from OFFSET on), or GET /healthz.
drive() {
  python3 - "$1" "$2" "$MODE" "$3" <<'EOF'
import http.client, sys
port, count, mode, offset = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
connection = http.client.HTTPConnection("127.0.0.1", port)
for i in range(count):
    if mode == "healthz":
        connection.request("GET", "/healthz")
    else:
        body = "{}" if mode == "cached" else '{"load": %.17g}' % (1e-9 * (1 + (offset + i) * 1e-9))
        connection.request("POST", "/v1/rolling", body, {"Content-Type": "application/json"})
    response = connection.getresponse()
    response.read()
    assert response.status == 200, response.status
EOF
}

# The instructions of BINARY answering the warm-up requests and then COUNT more.
total() {
  local binary="$1" count="$2" port=$((18200 + RANDOM % 500)) out
  out=$(mktemp)
  RUST_LOG=warn valgrind --tool=callgrind --callgrind-out-file="$out" \
    "$binary" serve --bind "127.0.0.1:$port" --database :memory: >/dev/null 2>&1 &
  local server=$!
  wait_ready "http://127.0.0.1:$port" 300 0.2
  drive "$port" 300 7000000
  drive "$port" "$count" 0
  kill -TERM "$server"
  wait "$server" 2>/dev/null || true
  awk '/^summary:/ {print $2}' "$out"
  rm -f "$out"
}

for binary in "$@"; do
  with=$(total "$binary" "$N")
  without=$(total "$binary" 0)
  awk -v b="$binary" -v m="$MODE" -v w="$with" -v o="$without" -v n="$N" \
    'BEGIN { printf "%s %s %.0f instructions a request\n", b, m, (w - o) / n }'
done
