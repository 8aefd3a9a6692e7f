"""Memory under sustained job submission: for 60 s, clients submit distinct sweep jobs as
fast as they are taken and re-post one cached job, while the server's resident memory is
sampled every second, with a small memory budget (8 MiB) so that growth beyond it shows.
Prints the RSS at the start, its maximum and at the end. Usage: reliability/memory.py [s]"""

import collections
import json
import sys
import threading

from common import Server, request, run_for, supports

SECONDS = float(sys.argv[1]) if len(sys.argv) > 1 else 60
BUDGET = 8 << 20

stop = threading.Event()
statuses = collections.Counter()


def outcome(answer):
    """The status of an answer, with the problem's name for a refusal (`503 results-full`:
    no room to keep the job's result, an honest no rather than a fault)."""
    status, body = answer[0], answer[1]
    if status >= 400:
        try:
            name = json.loads(body)["type"].rsplit("/", 1)[-1]
            return f"{status} {name}"
        except (ValueError, KeyError, AttributeError):
            pass
    return str(status)


def distinct(n):
    i = 0
    while not stop.is_set():
        i += 1
        loads = [f"{1 + ((n * 7919 + i) * 104729 + k) % 1_000_000 / 1e6} nN" for k in range(20)]
        job = {"kind": "sweep", "input": {"vary": {"load": loads}}}
        try:
            statuses[f"distinct {outcome(request(port, 'POST', '/v1/jobs', job))}"] += 1
        except OSError as e:
            statuses[f"distinct error {type(e).__name__}"] += 1


def same():
    job = {"kind": "rolling"}
    while not stop.is_set():
        try:
            statuses[f"cached {outcome(request(port, 'POST', '/v1/jobs', job))}"] += 1
        except OSError as e:
            statuses[f"cached error {type(e).__name__}"] += 1


budget_flag = "--memory-budget" if supports("--memory-budget") else "--cache-bytes"
with Server(budget_flag, str(BUDGET), "--max-queued-jobs", "64") as server:
    port = server.port
    start_rss = server.rss_mib()
    threads = [threading.Thread(target=distinct, args=(n,)) for n in range(4)]
    threads += [threading.Thread(target=same) for _ in range(4)]
    samples = run_for(SECONDS, threads, stop, server.rss_mib)
    print(f"memory: {budget_flag} {BUDGET >> 20} MiB, {SECONDS:.0f} s of submissions")
    print(
        f"RSS: start {start_rss:.0f} MiB, max {max(samples):.0f} MiB, "
        f"end {samples[-1]:.0f} MiB"
    )
    print("answers: " + ", ".join(f"{k}: {v}" for k, v in sorted(statuses.items())))
