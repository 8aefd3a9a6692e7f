"""SIGKILL and restart: a server takes a job, is killed, and a new one starts in its place;
the job's client asks for it there. Prints what it is told. Usage: reliability/sigkill.py"""

import json
import os
import shutil
import tempfile

from common import Server, request

# The database of saved analyses outlives the process: the new server opens the old one's.
data = tempfile.mkdtemp(prefix="thirdbody-sigkill-")
database = ("--database", os.path.join(data, "thirdbody.db"))

with Server("--max-sweep-points", "1000000", *database) as first:
    sweep = {"kind": "sweep", "input": {"base": {"options": {"strips": 128}}, "vary": {
        "radius": [f"{25 + i} nm" for i in range(50)],
        "load": [f"{1000 + i} pN" for i in range(50)]}}}
    status, body, _ = request(first.port, "POST", "/v1/jobs", sweep)
    job_id = json.loads(body)["id"]
    first.proc.kill()
    first.proc.wait()
    port = first.port

with Server(*database) as second:
    status, body, _ = request(second.port, "GET", f"/v1/jobs/{job_id}/result")
    problem = json.loads(body)
    print("sigkill: a job accepted, the server killed (SIGKILL) and started again")
    print(f"the job's result now answers {status} {problem.get('type', '')}: {problem.get('detail', '')}")
shutil.rmtree(data, ignore_errors=True)
