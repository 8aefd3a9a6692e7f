"""Large checks suites, each POST /v1/checks just under the default 1 MiB body limit, on a
server of their own:
- `checks suite`: about 930 kB of checks, 7,300 rolling jobs each with one expectation;
- `checks of sweeps`: 332 checks of 10,000-point sweeps (3.3 million points, 6.7 MB of JSON
  an answer), each expecting something of every point and of the sweep's counts.
Prints each answer's status and time and the server's RSS before, at its peak during the
suite, and 5 s after it (idle). Usage: reliability/checks_memory.py"""

import json
import threading
import time

from common import Server, request

ROLLING = [
    {
        "name": f"c{i}",
        "job": {"kind": "rolling", "input": {"load": f"{1 + i / 1e5} nN"}},
        "expect": {"friction_coefficient": {"max": 1}},
    }
    for i in range(7300)
]


def sweep(i):
    """A sweep of 100 loads by 100 speeds, its loads shifted by the check's index (so that
    no two checks share an answer)."""
    loads = [float(f"{(1 + j / 100 + i / 1e4) * 1e-9:.6g}") for j in range(100)]
    speeds = [float(f"{(1 + j / 50) * 1e-9:.4g}") for j in range(100)]
    return {"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}}


SWEEPS = [
    {
        "name": f"s{i}",
        "job": sweep(i),
        "expect": {
            "points[].friction_coefficient": {"max": 1},
            "meta.counts.refused": {"max": 0},
        },
    }
    for i in range(332)
]


def measure(name, checks, *flags):
    body = json.dumps({"checks": checks}).encode()
    with Server(*flags) as server:
        before = server.rss_mib()
        peak, stop = [before], threading.Event()

        def sample():
            while not stop.is_set():
                peak[0] = max(peak[0], server.rss_mib())
                time.sleep(0.05)

        sampler = threading.Thread(target=sample)
        sampler.start()
        try:
            status, _, seconds = request(server.port, "POST", "/v1/checks", body, timeout=120)
        finally:
            stop.set()
            sampler.join()
        time.sleep(5)
        print(
            f"{name}: {len(body) / 1e3:.0f} kB, {len(checks)} checks: status {status} in "
            f"{seconds:.1f} s, RSS {before:.0f} -> peak {peak[0]:.0f} MiB, idle "
            f"{server.rss_mib():.0f} MiB"
        )


measure("checks suite", ROLLING)
# The sweeps take about 20 s of one core: a deadline of 90 s (not the default 30 s) keeps a
# slow CI machine measuring memory rather than the deadline (a request may take 30 s more).
measure("checks of sweeps", SWEEPS, "--solve-deadline", "90s")
