"""SIGTERM with work in flight: a server with one solver thread takes a long job (running)
and four short ones (queued behind it), then gets SIGTERM. Every job's client keeps polling
it until it ends or the server is gone; a client the server left before it read its job asks
a server started again on the same database of saved analyses (the drain does not wait for
clients whose jobs that file keeps). Prints how many accepted jobs were answered, and how
many were lost. Then a job the shutdown timeout cannot fit, polled by five clients once a
second: prints how many read its fate (`interrupted`) before the port closed.
Usage: reliability/sigterm.py"""

import json
import os
import shutil
import signal
import tempfile
import threading
import time

from common import Server, request

GONE = "lost (server gone before it answered)"

def fate(port, job_id, every, gone):
    """Polls the job every `every` seconds until it ends; its final status, or `gone`
    (formatted with the error's name) once the server no longer answers."""
    while True:
        try:
            status, body, _ = request(port, "GET", f"/v1/jobs/{job_id}", timeout=5)
        except OSError as e:
            return gone.format(type(e).__name__)
        state = json.loads(body).get("status") if status == 200 else f"HTTP {status}"
        if state not in ("queued", "running"):
            return state
        time.sleep(every)


data = tempfile.mkdtemp(prefix="thirdbody-sigterm-")
database = ("--database", os.path.join(data, "thirdbody.db"))
with Server("--pool-size", "1", "--max-sweep-points", "1000000", "--shutdown-timeout", "60s",
            *database) as server:
    port = server.port
    # Its own rule keeps every point an exact strip solve (not a table look-up): seconds.
    long_sweep = {"kind": "sweep", "input": {"base": {"options": {"strips": 1024}}, "vary": {
        "radius": [f"{25 + i} nm" for i in range(20)],
        "load": [f"{1000 + i} pN" for i in range(20)],
        "velocity": [f"{1 + i} nm/s" for i in range(30)]}}}
    jobs = [request(port, "POST", "/v1/jobs", long_sweep)]
    for k in range(4):
        jobs.append(request(port, "POST", "/v1/jobs", {"kind": "rolling", "input": {"load": f"{1 + k / 10} nN"}}))
    ids = [json.loads(body)["id"] for status, body, _ in jobs if status == 202]
    time.sleep(0.3)
    server.proc.send_signal(signal.SIGTERM)
    sent = time.time()
    final = {}

    def follow(job_id):
        final[job_id] = fate(port, job_id, every=0.05, gone=GONE)

    threads = [threading.Thread(target=follow, args=(i,)) for i in ids]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    server.proc.wait(timeout=120)
    exited = time.time() - sent
    code = server.proc.returncode
# The jobs the server left before their clients read them, read where the file keeps them.
left = [job_id for job_id, state in final.items() if state == GONE]
with Server(*database) as again:
    for job_id in left:
        final[job_id] = fate(again.port, job_id, every=0.05, gone=GONE)
shutil.rmtree(data, ignore_errors=True)
answered = sum(1 for s in final.values() if s == "succeeded")
print(f"sigterm: {len(ids)} jobs accepted (1 running, {len(ids) - 1} queued), then SIGTERM")
print(f"answered {answered}, lost {len(ids) - answered}: " + ", ".join(sorted(final.values())))
print(f"the server exited {exited:.1f} s after SIGTERM, status {code}; {len(left)} read after "
      "a restart on the same database")


def pollers_of_an_interrupted_job():
    with Server("--max-sweep-points", "1000000", "--shutdown-timeout", "6s") as server:
        port = server.port
        sweep = {"kind": "sweep", "input": {"base": {"options": {"strips": 128}}, "vary": {
            "radius": [f"{25 + i} nm" for i in range(100)],
            "load": [f"{1000 + i} pN" for i in range(100)],
            "velocity": [f"{1 + i} nm/s" for i in range(30)]}}}
        status, body, _ = request(port, "POST", "/v1/jobs", sweep)
        job = json.loads(body)["id"]
        time.sleep(0.3)
        server.proc.send_signal(signal.SIGTERM)
        seen = {}

        def poll(k):
            time.sleep(0.2 * k)
            seen[k] = fate(port, job, every=1, gone="refused ({})")

        threads = [threading.Thread(target=poll, args=(k,)) for k in range(5)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        told = sum(1 for s in seen.values() if s == "interrupted")
        print(f"sigterm past the timeout: {told} of 5 pollers read the job interrupted: "
              + ", ".join(sorted(seen.values())))


pollers_of_an_interrupted_job()
