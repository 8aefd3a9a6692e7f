"""Admission by cost: on one job thread with --job-deadline 3s, a 1,000-point job teaches
the service what such points cost, a 27,000-point job (~7 s) is accepted, then a 1,331-point
job is submitted. Prints whether it was refused at once (with Retry-After) or accepted, and
then how it ended. Usage: reliability/queue_cost.py"""

import json
import time

from common import Server, request


def sweep(n):
    """A rolling sweep of about (n/2)^3 points of a slow rule (1,024 strips)."""
    m = (n + 1) // 2
    return {"kind": "sweep", "input": {"base": {"options": {"strips": 1024}}, "vary": {
        "radius": [f"{25 + i} nm" for i in range(m)],
        "load": [f"{1000 + n + i} pN" for i in range(m)],
        "velocity": [f"{1 + i} nm/s" for i in range(m)]}}}


def wait(port, job_id):
    while True:
        status, body, _ = request(port, "GET", f"/v1/jobs/{job_id}")
        job = json.loads(body)
        if job["status"] not in ("queued", "running"):
            return job
        time.sleep(0.2)


with Server("--pool-size", "2", "--job-deadline", "3s", "--max-sweep-points", "100000") as server:
    port = server.port
    status, body, _ = request(port, "POST", "/v1/jobs", sweep(20))
    wait(port, json.loads(body)["id"])
    request(port, "POST", "/v1/jobs", sweep(60))
    sent = time.time()
    status, body, _ = request(port, "POST", "/v1/jobs", sweep(22))
    answer = json.loads(body)
    if status == 202:
        job = wait(port, answer["id"])
        print(f"queue cost: a 1,331-point job behind ~7 s of work accepted (202), then "
              f"{job['status']} after {time.time() - sent:.1f} s, "
              f"{job['progress']['done']} of {job['progress']['total']} points done")
    else:
        print(f"queue cost: a 1,331-point job behind ~7 s of work refused at once ({status}): "
              f"{answer['detail']}")
