"""Bounded continuum work (issue 45): the continuum requests that took the process down are
refused at once, and a long continuum solve stops at its deadline. Prints, for each extreme,
its status, time and problem type, the server's RSS before and after, and the time a long
solve took to answer 504 past a 2 s deadline. Usage: reliability/continuum.py"""

import json
import time

from common import Server, request

# The extremes (53-byte requests), and a layer thinner still.
EXTREMES = [
    {"thickness": 1e-12},
    {"thickness": 1e-14},
    {"thickness": 1e-300},
    {"elastic_modulus": 1e-3},
    {"relaxation_time": 1e-30},
    {"retardation_time": 1e30},
]

# The largest grid the continuum plans (about 64,000 fine pixels): half a minute of solving.
LONGEST = {"layer": {"model": "continuum", "relaxation_time": 0.0027}}


def main():
    with Server() as server:
        before = server.rss_mib()
        slowest = 0.0
        for layer in EXTREMES:
            body = {"layer": {"model": "continuum", **layer}}
            status, payload, seconds = request(server.port, "POST", "/v1/rolling", body)
            slowest = max(slowest, seconds)
            problem = json.loads(payload).get("type", "").rsplit("/", 1)[-1]
            print(f"continuum extreme {json.dumps(layer)}: {status} {problem} "
                  f"in {seconds * 1000:.1f} ms")
        print(f"continuum extremes: slowest answer {slowest * 1000:.1f} ms, "
              f"RSS {before:.0f} -> {server.rss_mib():.0f} MiB, "
              f"server alive at the end: {server.proc.poll() is None}")
    with Server("--solve-deadline", "2s") as server:
        start = time.perf_counter()
        status, payload, _ = request(server.port, "POST", "/v1/rolling", LONGEST, timeout=120)
        seconds = time.perf_counter() - start
        problem = json.loads(payload).get("type", "").rsplit("/", 1)[-1]
        # The solver thread is free again: the next request is not refused as overloaded.
        after, _, _ = request(server.port, "POST", "/v1/rolling", {})
        print(f"continuum past a 2 s deadline: {status} {problem} after {seconds:.2f} s; "
              f"the next solve {after}")


if __name__ == "__main__":
    main()
