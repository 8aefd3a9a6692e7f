#!/usr/bin/env python3
"""The fleet on this machine (BENCHMARKS.md "Several processes on one Redis"):
a 10,000-point sweep through /v1/jobs on 1, 2 and 3 processes (one `serve`, the others
`worker`) sharing a Redis, and the cost of a cache hit from Redis (L2) against one from the
process's memory (L1). Needs redis-server and the release build (target/release/thirdbody)."""
import json, os, socket, statistics, subprocess, sys, time, urllib.request

BIN = os.environ.get("THIRDBODY_BIN", "target/release/thirdbody")

def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]

def wait_port(port):
    for _ in range(400):
        try:
            socket.create_connection(("127.0.0.1", port), 0.1).close()
            return
        except OSError:
            time.sleep(0.025)
    raise SystemExit(f"nothing on port {port}")

def request(url, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, headers={"content-type": "application/json"})
    with urllib.request.urlopen(req) as r:
        return r.status, dict(r.headers), r.read()

def start(cmd, redis, port=None):
    args = [BIN, cmd, "--redis-url", f"redis://127.0.0.1:{redis}", "--pool-size", "2"]
    if port:
        args += ["--bind", f"127.0.0.1:{port}"]
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

def sweep(tag):
    loads = [f"{1 + 0.01 * i + tag * 1e-4} nN" for i in range(100)]
    speeds = [f"{i} nm/s" for i in range(100)]
    return {"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}}

def timed_sweep(base, tag):
    start = time.perf_counter()
    _, _, body = request(f"{base}/v1/jobs", sweep(tag))
    job = json.loads(body)["id"]
    while True:
        _, _, body = request(f"{base}/v1/jobs/{job}")
        view = json.loads(body)
        if view["status"] not in ("queued", "running"):
            assert view["status"] == "succeeded", view
            return time.perf_counter() - start
        time.sleep(0.01)

def main():
    redis_port = free_port()
    redis = subprocess.Popen(["redis-server", "--port", str(redis_port), "--save", "",
                              "--appendonly", "no"], stdout=subprocess.DEVNULL)
    wait_port(redis_port)
    procs = []
    try:
        port = free_port()
        procs.append(start("serve", redis_port, port))
        wait_port(port)
        base = f"http://127.0.0.1:{port}"
        for n in (1, 2, 3):
            while len(procs) < n:
                procs.append(start("worker", redis_port))
            time.sleep(0.5)
            runs = [timed_sweep(base, 10 * n + k) for k in range(3)]
            print(f"10,000-point sweep on {n} process(es): median {statistics.median(runs):.2f} s "
                  f"(runs: {', '.join(f'{r:.2f}' for r in runs)})")
        # L1 and L2 hits: answers solved on A, read on B (first from Redis, then from memory).
        port_b = free_port()
        procs.append(start("serve", redis_port, port_b))
        wait_port(port_b)
        b = f"http://127.0.0.1:{port_b}"
        bodies = [{"load": f"{1 + i * 1e-3} nN"} for i in range(300)]
        for body in bodies:
            request(f"{base}/v1/rolling", body)
        l2, l1 = [], []
        for body in bodies:
            t = time.perf_counter(); _, h, _ = request(f"{b}/v1/rolling", body); l2.append(time.perf_counter() - t)
            assert h["x-cache"] == "hit"
            t = time.perf_counter(); request(f"{b}/v1/rolling", body); l1.append(time.perf_counter() - t)
        ms = lambda xs: f"median {1e3 * statistics.median(xs):.3f} ms, p90 {1e3 * statistics.quantiles(xs, n=10)[-1]:.3f} ms"
        print(f"hit from Redis (L2), whole request: {ms(l2)}")
        print(f"hit from memory (L1), whole request: {ms(l1)}")
    finally:
        for p in procs:
            p.kill()
        redis.kill()

if __name__ == "__main__":
    main()
