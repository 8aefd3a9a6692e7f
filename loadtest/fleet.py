#!/usr/bin/env python3
"""The fleet on this machine (BENCHMARKS.md "A fleet that scales"): a light sweep (10,000
rolling points, default rule) and two heavy ones (three-body points; rolling points on the
layer as a continuum) through /v1/jobs, on one
`serve` without Redis and on one `serve` with Redis plus 0, 1 and 2 `worker`s; for each,
the wall time from submission to the result in hand, and what Redis spent on the job: its
command time (INFO commandstats) and the bytes it took in and sent out (INFO stats), per point.
Then the cost of a cache hit from Redis (L2) against one from the process's memory (L1).

    python3 loadtest/fleet.py [--runs N] [--sweeps light,heavy,continuum] [--svg FILE] [NAME=BINARY ...]

Builds given as NAME=BINARY are measured one after the other in the same run (default: one,
new=target/release/thirdbody); --svg draws the medians as a bar chart. Needs redis-server."""
import argparse, json, os, socket, statistics, subprocess, time, urllib.request

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

def start(binary, cmd, redis=None, port=None):
    args = [binary, cmd, "--pool-size", "2"]
    if redis:
        args += ["--redis-url", f"redis://127.0.0.1:{redis}"]
    if port:
        args += ["--bind", f"127.0.0.1:{port}"]
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

def light(tag):
    """10,000 rolling points; `tag` makes every run's answers new (no cache hit)."""
    loads = [f"{1 + 0.01 * i + tag * 1e-5} nN" for i in range(100)]
    speeds = [f"{i} nm/s" for i in range(100)]
    return {"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}}, 10_000

def heavy(tag):
    """400 three-body points (20 loads x 20 speeds), each a population of particles."""
    loads = [f"{0.5 + 0.05 * i + tag * 1e-5} mN" for i in range(20)]
    speeds = [f"{1 + i} nm/s" for i in range(20)]
    return {"kind": "sweep", "input": {"kind": "three_body",
            "vary": {"total_load": loads, "velocity": speeds}}}, 400

def continuum(tag):
    """60 rolling points on the layer as a continuum (4 loads x 15 speeds), ~25 ms each."""
    loads = [f"{1 + 0.2 * i + tag * 1e-5} nN" for i in range(4)]
    speeds = [f"{0.2 * (1 + i)} nm/s" for i in range(15)]
    return {"kind": "sweep", "input": {"base": {"layer": {"model": "continuum"}},
            "vary": {"load": loads, "velocity": speeds}}}, 60

class Redis:
    def __init__(self, port):
        self.port = port

    def info(self, section):
        out = subprocess.run(["redis-cli", "-p", str(self.port), "info", section],
                             capture_output=True, text=True, check=True).stdout
        return dict(l.split(":", 1) for l in out.splitlines() if ":" in l)

    def snapshot(self):
        stats = self.info("stats")
        usec = sum(int(dict(kv.split("=") for kv in v.split(","))["usec"])
                   for k, v in self.info("commandstats").items() if k.startswith("cmdstat_"))
        return usec, int(stats["total_net_input_bytes"]), int(stats["total_net_output_bytes"])

def timed_job(base, job, points, redis):
    before = redis.snapshot() if redis else None
    start = time.perf_counter()
    _, _, body = request(f"{base}/v1/jobs", job)
    view = json.loads(body)
    while view["status"] in ("queued", "running"):
        time.sleep(0.005)
        _, _, body = request(f"{base}/v1/jobs/{view['id']}")
        view = json.loads(body)
    assert view["status"] == "succeeded", view
    _, _, result = request(f"{base}/v1/jobs/{view['id']}/result")
    wall = time.perf_counter() - start
    assert len(json.loads(result)["points"]) == points
    if not redis:
        return wall, 0.0, 0.0
    after = redis.snapshot()
    return (wall, (after[0] - before[0]) / points,
            (after[1] - before[1] + after[2] - before[2]) / points)

SWEEPS = {"light": light, "heavy": heavy, "continuum": continuum}

def layouts(binary, redis_port, runs, tags, sweeps):
    """Yields (layout, sweep, medians) for every layout of one build."""
    for workers in (None, 0, 1, 2):
        redis = Redis(redis_port) if workers is not None else None
        if redis:
            subprocess.run(["redis-cli", "-p", str(redis_port), "flushall"], check=True,
                           capture_output=True)
        port = free_port()
        procs = [start(binary, "serve", redis_port if redis else None, port)]
        procs += [start(binary, "worker", redis_port) for _ in range(workers or 0)]
        try:
            wait_port(port)
            time.sleep(0.5)
            base = f"http://127.0.0.1:{port}"
            name = "alone" if redis is None else f"redis + {workers} worker(s)"
            for sweep_name in sweeps:
                make = SWEEPS[sweep_name]
                results = [timed_job(base, *make(next(tags)), redis) for _ in range(runs)]
                medians = [statistics.median(r[i] for r in results) for i in range(3)]
                yield name, sweep_name, medians
        finally:
            for p in procs:
                p.kill()
                p.wait()

def hits(binary, redis_port):
    port_a, port_b = free_port(), free_port()
    procs = [start(binary, "serve", redis_port, port_a), start(binary, "serve", redis_port, port_b)]
    try:
        wait_port(port_a); wait_port(port_b)
        a, b = f"http://127.0.0.1:{port_a}", f"http://127.0.0.1:{port_b}"
        bodies = [{"load": f"{1 + i * 1e-3} nN"} for i in range(300)]
        for body in bodies:
            request(f"{a}/v1/rolling", body)
        l2, l1 = [], []
        for body in bodies:
            t = time.perf_counter(); _, h, _ = request(f"{b}/v1/rolling", body); l2.append(time.perf_counter() - t)
            assert h["x-cache"] == "hit"
            t = time.perf_counter(); request(f"{b}/v1/rolling", body); l1.append(time.perf_counter() - t)
        return statistics.median(l2), statistics.median(l1)
    finally:
        for p in procs:
            p.kill()
            p.wait()

def chart(rows, path):
    """Grouped horizontal bars: one group per (sweep, layout), one bar per build; each
    sweep's bars to its own scale (its slowest run the full width)."""
    builds = sorted({r[0] for r in rows}, key=[r[0] for r in rows].index)
    layouts = sorted({r[1] for r in rows}, key=[r[1] for r in rows].index)
    colours = ["#9aa5b1", "#1f6feb", "#d97706", "#16a34a"]
    groups = []
    for sweep in ("light", "heavy", "continuum"):
        top = max((r[3] for r in rows if r[2] == sweep), default=1.0)
        for layout in layouts:
            bars = [(b, r[3]) for b in builds for r in rows if r[:3] == (b, layout, sweep)]
            if bars:
                groups.append((f"{sweep}: {layout}", bars, top))
    bar, gap, left, width = 14, 10, 190, 420
    height = 40 + len(groups) * (len(builds) * bar + gap) + 20 * len(builds)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{left + width + 80}" height="{height}" '
           'font-family="sans-serif" font-size="12">',
           '<text x="10" y="20" font-weight="bold">Sweep through /v1/jobs, wall time '
           '(median, s; each sweep to its own scale)</text>']
    y = 36
    for label, bars, top in groups:
        out.append(f'<text x="{left - 6}" y="{y + bar * len(bars) / 2 + 4}" text-anchor="end">{label}</text>')
        for build, value in bars:
            w = width * value / top
            c = colours[builds.index(build) % len(colours)]
            out.append(f'<rect x="{left}" y="{y}" width="{w:.1f}" height="{bar - 2}" fill="{c}"/>')
            out.append(f'<text x="{left + w + 4:.1f}" y="{y + bar - 4}">{value:.3f}</text>')
            y += bar
        y += gap
    for i, build in enumerate(builds):
        out.append(f'<rect x="{left}" y="{y + 20 * i}" width="12" height="12" fill="{colours[i % len(colours)]}"/>')
        out.append(f'<text x="{left + 18}" y="{y + 20 * i + 10}">{build}</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")

def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--sweeps", default="light,heavy,continuum")
    parser.add_argument("--svg")
    parser.add_argument("builds", nargs="*", default=["new=target/release/thirdbody"])
    args = parser.parse_args()
    builds = [b.split("=", 1) for b in args.builds]
    redis_port = free_port()
    redis = subprocess.Popen(["redis-server", "--port", str(redis_port), "--save", "",
                              "--appendonly", "no"], stdout=subprocess.DEVNULL)
    wait_port(redis_port)
    tags = iter(range(1, 1_000_000))
    rows = []
    try:
        print("| build | layout | sweep | wall (median) | Redis command time per point | Redis bytes per point |")
        print("|---|---|---|---|---|---|")
        for name, binary in builds:
            for layout, sweep, (wall, usec, size) in layouts(binary, redis_port, args.runs, tags, args.sweeps.split(",")):
                rows.append((name, layout, sweep, wall))
                print(f"| {name} | {layout} | {sweep} | {wall:.3f} s | {usec:.2f} µs | {size:,.0f} B |",
                      flush=True)
        for name, binary in builds:
            l2, l1 = hits(binary, redis_port)
            print(f"{name}: a hit from Redis (L2) {1e3 * l2:.3f} ms, from memory (L1) {1e3 * l1:.3f} ms "
                  "(median of 300, whole request)")
    finally:
        redis.kill()
    if args.svg:
        chart(rows, args.svg)

if __name__ == "__main__":
    main()
