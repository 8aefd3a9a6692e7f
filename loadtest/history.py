#!/usr/bin/env python3
"""What saving every job costs (BENCHMARKS.md "Saved analyses"): one `serve` without Redis,
each build measured in turn in the same run, on the same jobs:

- a 10,000-point rolling sweep through /v1/jobs: the wall time from submission to the
  result in hand (its result is the largest the defaults allow: it is written to the
  database whole);
- 200 one-point jobs submitted one after the other, each read to its end: the time per job
  (three small writes each: accepted, started, finished);
- the database's size after all of it, and `GET /v1/jobs` (a page of 20) with 1,000 jobs
  in the owner's history.

    python3 loadtest/history.py [--runs N] [NAME=BINARY[:FLAGS] ...]

FLAGS are extra `serve` flags, comma-separated (e.g. new=target/release/thirdbody:--database,:memory:).
A build without `--database` (before the history) is run as it is."""
import argparse, json, os, shutil, socket, statistics, subprocess, tempfile, time, urllib.request

OWNER = {"thirdbody-owner": "history-benchmark-token-0001"}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def request(url, body=None, headers=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, headers={"content-type": "application/json", **(headers or {})})
    with urllib.request.urlopen(req) as r:
        return r.status, r.read()


def run_job(base, job):
    """Submits `job`, polls it to its end, reads its result; the wall time in seconds."""
    start = time.perf_counter()
    _, body = request(f"{base}/v1/jobs", job, OWNER)
    view = json.loads(body)
    while view["status"] in ("queued", "running"):
        time.sleep(0.002)
        view = json.loads(request(f"{base}/v1/jobs/{view['id']}")[1])
    assert view["status"] == "succeeded", view
    request(base + view["result_url"])
    return time.perf_counter() - start


def big_sweep(tag):
    loads = [f"{1 + 0.01 * i + tag * 1e-5} nN" for i in range(100)]
    speeds = [f"{i} nm/s" for i in range(100)]
    return {"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}}


def one_point(tag):
    return {"kind": "rolling", "input": {"load": f"{1 + tag * 1e-6} nN"}}


def measure(name, binary, flags, runs, tag):
    data = tempfile.mkdtemp(prefix="thirdbody-history-bench-")
    help_text = subprocess.run([binary, "serve", "--help"], capture_output=True, text=True).stdout
    args = [binary, "serve", "--pool-size", "2", "--bind", f"127.0.0.1:{free_port()}"]
    port = int(args[-1].rsplit(":", 1)[1])
    database = os.path.join(data, "thirdbody.db")
    if "--database" in help_text and "--database" not in flags:
        args += ["--database", database]
    proc = subprocess.Popen(args + flags, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}"
    try:
        for _ in range(400):
            try:
                request(f"{base}/healthz")
                break
            except OSError:
                time.sleep(0.025)
        run_job(base, big_sweep(tag))  # warm-up
        big = [run_job(base, big_sweep(tag + 1 + i)) for i in range(runs)]
        small = []
        for i in range(200):
            small.append(run_job(base, one_point(tag * 1000 + i)))
        for i in range(1000 - 200 - runs - 1):
            request(f"{base}/v1/jobs", one_point(tag * 100000 + i), OWNER)
        listing = None
        if "--database" in help_text:
            times = []
            for _ in range(50):
                start = time.perf_counter()
                status, body = request(f"{base}/v1/jobs?limit=20", headers=OWNER)
                times.append(time.perf_counter() - start)
            listing = (statistics.median(times), json.loads(body)["total"])
        size = sum(os.path.getsize(os.path.join(data, f)) for f in os.listdir(data))
        return {
            "name": name,
            "sweep_ms": statistics.median(big) * 1e3,
            "job_ms": statistics.median(small) * 1e3,
            "list_ms": listing and listing[0] * 1e3,
            "listed": listing and listing[1],
            "db_mb": size / 1e6,
        }
    finally:
        proc.terminate()
        proc.wait()
        shutil.rmtree(data, ignore_errors=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("builds", nargs="*", default=["new=target/release/thirdbody"])
    options = parser.parse_args()
    tag = int(time.time()) % 10000
    for i, build in enumerate(options.builds):
        name, spec = build.split("=", 1)
        binary, _, flags = spec.partition(":")
        row = measure(name, binary, [f for f in flags.split(",") if f], options.runs, tag + 10 * i)
        listed = f"{row['list_ms']:.2f} ms for a page of 20 of {row['listed']}" if row["list_ms"] else "no history"
        print(f"{row['name']:>12}: 10k-point sweep {row['sweep_ms']:.0f} ms, one-point job "
              f"{row['job_ms']:.2f} ms, {listed}, database {row['db_mb']:.1f} MB")


if __name__ == "__main__":
    main()
