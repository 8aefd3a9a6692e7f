"""What a 10,000-point rolling sweep costs, whole process, for each binary given (issue 20):
wall and CPU time per point of `thirdbody solve` with JSON and CSV output (the median of
ROUNDS runs, binaries interleaved), and the bytes per point of the answer as the service
sends it (compact JSON from POST /v1/sweeps, with and without gzip).

    python3 benches/sweep_cost.py [ROUNDS] BIN [BIN...]

Not part of CI: the figures go to BENCHMARKS.md.
"""

import json
import os
import resource
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

POINTS = 10_000
INPUT = {"vary": {"load": [f"{1000 + i} pN" for i in range(100)],
                  "velocity": [f"{v} nm/s" for v in range(100)]}}


def timed(args):
    """Wall and CPU (user + system, every thread) seconds of one run of `args`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return wall, cpu


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wire_bytes(binary):
    """Bytes of the sweep's JSON answer from the service, plain and gzipped."""
    port = free_port()
    server = subprocess.Popen([binary, "serve", "--bind", f"127.0.0.1:{port}"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        sizes = []
        for encoding in ("identity", "gzip"):
            for _ in range(100):
                try:
                    request = urllib.request.Request(
                        f"http://127.0.0.1:{port}/v1/sweeps", json.dumps(INPUT).encode(),
                        {"content-type": "application/json", "accept-encoding": encoding})
                    with urllib.request.urlopen(request) as response:
                        sizes.append(len(response.read()))
                    break
                except OSError:
                    time.sleep(0.05)
        return sizes
    finally:
        server.terminate()
        server.wait()


def main():
    args = sys.argv[1:]
    rounds = int(args.pop(0)) if args and args[0].isdigit() else 15
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as job:
        json.dump({"kind": "sweep", "input": INPUT}, job)
    runs = {(b, f): [] for b in args for f in ("json", "csv")}
    for _ in range(rounds):
        for binary in args:
            for form in ("json", "csv"):
                runs[(binary, form)].append(timed([binary, "solve", job.name, "--format", form]))
    os.unlink(job.name)
    for binary in args:
        plain, zipped = wire_bytes(binary)
        print(f"{binary}: JSON {plain / POINTS:.0f} B/point on the wire, "
              f"{zipped / POINTS:.0f} B/point with gzip")
        for form in ("json", "csv"):
            walls, cpus = zip(*runs[(binary, form)])
            print(f"  solve --format {form}: wall {statistics.median(walls) / POINTS * 1e6:.2f} "
                  f"µs/point, CPU {statistics.median(cpus) / POINTS * 1e6:.2f} µs/point")


if __name__ == "__main__":
    main()
