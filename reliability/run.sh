#!/usr/bin/env bash
# The reliability measurements of RELIABILITY.md, each printing its figure, against the
# release build (or THIRDBODY_BIN). `--bounded` runs shorter versions (as CI does) and fails
# when a promise is broken: a lost job, an unanswered /healthz, a server that died.
# `--keys` runs them with API keys required (every client, hostile ones too, presents one).
# Usage: reliability/run.sh [--bounded] [--keys]
set -euo pipefail
cd "$(dirname "$0")/.."
bounded=false
for flag in "$@"; do
  case "$flag" in
    --bounded) bounded=true ;;
    --keys) export THIRDBODY_RELIABILITY_KEYS=1 ;;
    *) echo "usage: reliability/run.sh [--bounded] [--keys]" >&2; exit 2 ;;
  esac
done
. reliability/binary.sh
if $bounded; then
  durations=(10 10 15 8)
else
  durations=(30 60 40 30)
fi
out=$(mktemp)
trap 'rm -f "$out"' EXIT
python3 reliability/overload.py "${durations[0]}" | tee -a "$out"
python3 reliability/memory.py "${durations[1]}" | tee -a "$out"
python3 reliability/slowloris.py "${durations[2]}" | tee -a "$out"
python3 reliability/hostile.py all "${durations[3]}" | tee -a "$out"
python3 reliability/checks_memory.py | tee -a "$out"
python3 reliability/queue_cost.py | tee -a "$out"
python3 reliability/sigterm.py | tee -a "$out"
python3 reliability/sigkill.py | tee -a "$out"
python3 reliability/continuum.py | tee -a "$out"
python3 reliability/full_disk.py | tee -a "$out"
if $bounded; then
  broken=0
  if grep -q "server alive at the end: False" "$out"; then echo "BROKEN: the server died"; broken=1; fi
  grep -qE "^answered [0-9]+, lost 0:" "$out" || { echo "BROKEN: an accepted job was lost"; broken=1; }
  if grep "failed (5 s timeout)" "$out" | grep -v ", 0 failed (5 s timeout)"; then
    echo "BROKEN: /healthz went unanswered"; broken=1
  fi
  # A checks suite near the body limit is answered within the default memory budget (256
  # MiB); one of 332 10,000-point sweeps peaks at 300 MiB at most and, its answers judged and
  # let go, leaves the process under 100 MiB when idle (issue 45).
  if ! awk '/^checks (suite|of sweeps): /{
          seen++; peak = $0; sub(/.* peak /, "", peak); idle = $0; sub(/.* idle /, "", idle)
          sweeps = /^checks of sweeps/
          if (!/ status 200 / || peak + 0 > (sweeps ? 300 : 255) || (sweeps && idle + 0 >= 100)) {
            print "  " $0; bad = 1
          }
        } END { exit bad || seen != 2 }' "$out"; then
    echo "BROKEN: a large checks suite went past its memory bound, or kept its memory"; broken=1
  fi
  # Under 511 hostile connections, a well-behaved client is served (RELIABILITY.md).
  if grep -E "well-behaved solves: .*\((9[0-8]|[0-8]?[0-9])\.[0-9] %\)" "$out"; then
    echo "BROKEN: fewer than 99 % of a well-behaved client's solves succeeded"; broken=1
  fi
  # ... and /healthz answers within 50 ms at the 99th percentile.
  if awk '/^hostile /{mode=$2} mode && /\/healthz:/{for(i=1;i<NF;i++) if($i=="p99") p=$(i+1);
          if(p+0 >= 50){print "  " mode " /healthz p99 " p " ms"; slow=1} mode=""}
          END{exit !slow}' "$out"; then
    echo "BROKEN: /healthz p99 reached 50 ms under hostile connections"; broken=1
  fi
  grep -q "queue cost: .* refused at once (429)" "$out" \
    || { echo "BROKEN: a job that could not end within its deadline was accepted"; broken=1; }
  grep -q "sigterm past the timeout: 5 of 5 pollers read the job interrupted" "$out" \
    || { echo "BROKEN: a poller of a job the shutdown interrupted was not told"; broken=1; }
  grep -q "answers 410 tag:thirdbody,2026:problems/interrupted" "$out" \
    || { echo "BROKEN: a restarted server does not say interrupted"; broken=1; }
  # On a full disk jobs are refused, never accepted and lost (a machine that cannot mount a
  # tmpfs says it skipped it).
  if grep -E "^full disk: .*lost [1-9]" "$out"; then echo "BROKEN: a job accepted on a full disk was lost"; broken=1; fi
  # The continuum's extremes are refused (422) before any work, and a long continuum solve
  # stops at its deadline (2 s; 3 s allows a loaded machine, the solve itself takes 30 s).
  [ "$(grep -cE '^continuum extreme .*: 422 ' "$out")" -eq 6 ] \
    || { echo "BROKEN: a continuum extreme was not refused with 422"; broken=1; }
  grep -qE "^continuum past a 2 s deadline: 504 deadline-exceeded after (2\.[0-9]+|1\.[0-9]+) s; the next solve 200" "$out" \
    || { echo "BROKEN: a continuum solve went on past its deadline"; broken=1; }
  # 503 results-full is a refusal the service owes (no room to keep a job's result for its
  # retention), not a fault.
  if grep -oE "(solve|hostile|distinct|cached) 5[0-9][0-9][^:,]*" "$out" | grep -v "results-full"; then
    echo "BROKEN: a 5xx answer"; broken=1
  fi
  exit $broken
fi
