#!/usr/bin/env bash
# Captures thirdbody's cached answer to `{}` (body and headers) for the bare server, after
# a change to the answer's bytes; then rebuild it (cargo build --release --locked here).
#
#   loadtest/bare/capture.sh [BINARY]     (default target/release/thirdbody)
set -euo pipefail
cd "$(dirname "$0")"
# shellcheck source=loadtest/lib.sh
source ../lib.sh
BINARY="${1:-../../target/release/thirdbody}"
PORT=18090
BASE="http://127.0.0.1:$PORT"
RUST_LOG=warn "$BINARY" serve --bind "127.0.0.1:$PORT" --database :memory: 2>/dev/null &
server=$!
trap 'kill "$server" 2>/dev/null || true' EXIT
wait_ready "$BASE"
post() {
  curl -sf -X POST -H 'content-type: application/json' -d '{}' "$@" "$BASE/v1/rolling"
}
post -o /dev/null
post -D src/rolling.headers.raw -o src/rolling.json
# Every header but the status line, the length and the date (hyper writes those).
tr -d '\r' <src/rolling.headers.raw | grep -v -i -E '^(HTTP/|content-length:|date:|$)' >src/rolling.headers
rm src/rolling.headers.raw
grep -q '^x-cache: hit$' src/rolling.headers
