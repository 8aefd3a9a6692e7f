"""Overload: for 30 s, 10 clients per core send uncached solves and 2 send hostile bodies
(sweeps of 60,000 bad values, 180 kB each), while a separate client asks /healthz every
20 ms and measures how long each answer takes. Prints the /healthz latencies and the
answers the others got. Usage: reliability/overload.py [seconds]"""

import collections
import json
import os
import sys
import threading
import time

from common import Server, latency_line, request, run_for

SECONDS = float(sys.argv[1]) if len(sys.argv) > 1 else 30
CORES = os.cpu_count() or 1
HOSTILE = json.dumps({"vary": {"radius": [-1] * 60000}}).encode()

stop = threading.Event()
statuses = collections.Counter()
health = []


def solver(n):
    i = 0
    while not stop.is_set():
        i += 1
        try:
            load = f"{1 + (n * 1_000_003 + i) % 400_000 / 1e6} nN"
            status = request(port, "POST", "/v1/rolling", {"load": load}, timeout=70)[0]
            statuses[f"solve {status}"] += 1
        except OSError as e:
            statuses[f"solve error {type(e).__name__}"] += 1


def hostile():
    while not stop.is_set():
        try:
            status = request(port, "POST", "/v1/sweeps", HOSTILE, timeout=70)[0]
            statuses[f"hostile {status}"] += 1
        except OSError as e:
            statuses[f"hostile error {type(e).__name__}"] += 1


rss = []


def sampler(server):
    while not stop.is_set():
        rss.append(server.rss_mib())
        time.sleep(1)


def prober():
    while not stop.is_set():
        start = time.perf_counter()
        try:
            request(port, "GET", "/healthz", timeout=70)
        except OSError:
            pass
        health.append(time.perf_counter() - start)
        time.sleep(0.02)


with Server() as server:
    port = server.port
    threads = [threading.Thread(target=solver, args=(n,)) for n in range(10 * CORES)]
    threads += [threading.Thread(target=hostile) for _ in range(2)]
    threads.append(threading.Thread(target=prober))
    threads.append(threading.Thread(target=sampler, args=(server,)))
    run_for(SECONDS, threads, stop)
    alive = server.proc.poll() is None
    print(f"overload: {CORES} cores, {10 * CORES} solving clients, 2 hostile, {SECONDS:.0f} s")
    print(latency_line("/healthz", health))
    print("answers: " + ", ".join(f"{k}: {v}" for k, v in sorted(statuses.items())))
    print(f"RSS: max {max(rss):.0f} MiB (default memory budget 256 MiB)")
    print(f"server alive at the end: {alive}")
