"""Wall time of a sweep run as a job by one `thirdbody serve`, submit to succeeded, against
the same sweep from the command line (issue 47: "a 64-point continuum sweep on one serve
against the CLI, within 1.2x").

    python3 benches/serve_sweep.py SWEEP.json [RUNS] [SERVE FLAGS...]
    e.g. python3 benches/serve_sweep.py benches/sweep64.json 3

Each run moves the sweep's base radius by 1 nm, so that no point is cached or recalled from
the memo; the job is polled every 20 ms. Not part of CI: a yardstick for BENCHMARKS.md.
"""

import json
import subprocess
import sys
import time
import urllib.request

BINARY = "target/release/thirdbody"
job_file, runs, flags = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 3, sys.argv[3:]
job = json.load(open(job_file))
port = 18555
server = subprocess.Popen(
    [BINARY, "serve", "--bind", f"127.0.0.1:{port}", "--database", ":memory:", *flags],
    stdout=subprocess.DEVNULL,
    stderr=subprocess.DEVNULL,
)
base = f"http://127.0.0.1:{port}"
for _ in range(100):
    try:
        urllib.request.urlopen(base + "/healthz")
        break
    except OSError:
        time.sleep(0.1)
try:
    for run in range(runs):
        job["input"].setdefault("base", {})["radius"] = f"{25 + run} nm"
        start = time.time()
        body = json.dumps(job).encode()
        request = urllib.request.Request(base + "/v1/jobs", body, {"content-type": "application/json"})
        location = urllib.request.urlopen(request).headers["location"]
        while True:
            view = json.load(urllib.request.urlopen(base + location))
            if view["status"] not in ("queued", "running"):
                break
            time.sleep(0.02)
        served = time.time() - start
        json.dump(job, open("/tmp/serve_sweep_job.json", "w"))
        start = time.time()
        subprocess.run([BINARY, "solve", "/tmp/serve_sweep_job.json", "--format", "csv"],
                       stdout=subprocess.DEVNULL, check=True)
        print(f"R = {25 + run} nm: serve {view['status']} {served:.2f} s, "
              f"command line {time.time() - start:.2f} s")
finally:
    server.terminate()
