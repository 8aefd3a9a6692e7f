"""The memory of one pod of deploy/base: a `thirdbody serve` with the settings of its
ConfigMap (read from deploy/base/kustomization.yaml: the pool, the memory budget) on a fleet
Redis of its own, under every kind of load at once for N s: clients asking for distinct
solves (the cache fills to its share of the budget), clients submitting sweeps of 2,000
points as jobs and reading their answers back, clients posting the largest bodies the
limit lets in (sweeps of bad values, refused after reading), and a checks suite of 7,300
checks. Prints the RSS sampled every 0.2 s: its maximum is what the Deployment's memory
request must hold, with room for the limit. Usage: reliability/pod_memory.py [seconds]"""

import collections
import json
import os
import subprocess
import sys
import threading
import time

import yaml

from common import ROOT, Server, free_port, request, run_for

SECONDS = float(sys.argv[1]) if len(sys.argv) > 1 else 60

kustomization = yaml.safe_load(open(os.path.join(ROOT, "deploy", "base", "kustomization.yaml")))
settings = dict(
    literal.split("=", 1)
    for generator in kustomization["configMapGenerator"]
    for literal in generator["literals"]
)
flags = []
for name, value in settings.items():
    flags += ["--" + name.removeprefix("THIRDBODY_").lower().replace("_", "-"), value]

stop = threading.Event()
statuses = collections.Counter()


def solves(n):
    i = 0
    while not stop.is_set():
        i += 1
        load = f"{1 + (n * 1_000_003 + i) % 900_000 / 1e6} nN"
        try:
            status = request(port, "POST", "/v1/rolling", {"load": load}, timeout=70)[0]
            statuses[f"solve {status}"] += 1
        except OSError as e:
            statuses[f"solve error {type(e).__name__}"] += 1


def sweeps(n):
    i = 0
    while not stop.is_set():
        i += 1
        speeds = [f"{(n * 7919 + i) % 1000 + k / 100} nm/s" for k in range(50)]
        loads = [f"{1 + k / 20} nN" for k in range(40)]
        job = {"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}}
        try:
            status, body, _ = request(port, "POST", "/v1/jobs", job, timeout=70)
            statuses[f"sweep job {status}"] += 1
            if status != 202:
                time.sleep(0.5)
                continue
            location = f"/v1/jobs/{json.loads(body)['id']}"
            while not stop.is_set():
                view = json.loads(request(port, "GET", location, timeout=70)[1])
                if view["status"] not in ("queued", "running"):
                    break
                time.sleep(0.2)
            status = request(port, "GET", location + "/result", timeout=70)[0]
            statuses[f"sweep result {status}"] += 1
        except (OSError, ValueError, KeyError) as e:
            statuses[f"sweep error {type(e).__name__}"] += 1


def bodies():
    # Just under the default body limit, 1 MiB.
    body = json.dumps({"vary": {"radius": [-1] * 262_000}}).encode()
    while not stop.is_set():
        try:
            statuses[f"large body {request(port, 'POST', '/v1/sweeps', body, timeout=70)[0]}"] += 1
        except OSError as e:
            statuses[f"large body error {type(e).__name__}"] += 1


def checks():
    suite = {"checks": [
        {"name": f"c{i}", "job": {"kind": "rolling", "input": {"load": f"{1 + i / 1e4} nN"}},
         "expect": {"friction_coefficient": {"max": 1}}}
        for i in range(7300)
    ]}
    while not stop.is_set():
        try:
            statuses[f"checks {request(port, 'POST', '/v1/checks', suite, timeout=120)[0]}"] += 1
        except OSError as e:
            statuses[f"checks error {type(e).__name__}"] += 1


redis_port = free_port()
redis = subprocess.Popen(
    ["redis-server", "--port", str(redis_port), "--bind", "127.0.0.1", "--save", "",
     "--appendonly", "no"],
    stdout=subprocess.DEVNULL,
)
try:
    time.sleep(0.5)
    url = f"redis://127.0.0.1:{redis_port}"
    with Server("--redis-url", url, *flags) as server:
        port = server.port
        start_rss = server.rss_mib()
        threads = [threading.Thread(target=solves, args=(n,)) for n in range(6)]
        threads += [threading.Thread(target=sweeps, args=(n,)) for n in range(2)]
        threads += [threading.Thread(target=bodies) for _ in range(2)]
        threads += [threading.Thread(target=checks)]
        samples = run_for(SECONDS, threads, stop, server.rss_mib, every=0.2)
        print(f"pod memory: {' '.join(flags)}, on Redis, {SECONDS:.0f} s of mixed load")
        print(
            f"RSS: start {start_rss:.0f} MiB, max {max(samples):.0f} MiB, "
            f"end {samples[-1]:.0f} MiB, server alive at the end: {server.proc.poll() is None}"
        )
        print("answers: " + ", ".join(f"{k}: {v}" for k, v in sorted(statuses.items())))
finally:
    redis.kill()
    redis.wait()
