"""Nothing accepted is lost on a full disk (issue 45): `serve` with its database on a small
tmpfs, 300 submissions of distinct jobs, the tmpfs filled to its last byte after the first
20, the room freed,
a restart, and every job that was accepted read back. Needs root (to mount the tmpfs); says
it was skipped otherwise. Prints the submissions accepted and refused, what /readyz said
while the disk was full, and how many accepted jobs the restarted server has, finished.
Usage: reliability/full_disk.py"""

import json
import os
import subprocess
import tempfile
import time

from common import Server, request


def fill(path):
    """Writes zeros to `path` until the filesystem has no room left."""
    block = bytes(4096)
    with open(path, "wb", buffering=0) as filler:
        for size in (block, block[:1]):
            try:
                while True:
                    filler.write(size)
            except OSError:
                pass


def finished(port, job):
    """The job's view once it has finished (bounded: a rolling job takes microseconds)."""
    deadline = time.time() + 120
    while True:
        status, body, _ = request(port, "GET", f"/v1/jobs/{job}")
        view = json.loads(body) if status == 200 else {"status": status}
        if view.get("status") not in ("queued", "running") or time.time() > deadline:
            return view
        time.sleep(0.02)


def main():
    mount = tempfile.mkdtemp(prefix="thirdbody-full-disk-")
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", mount],
                          capture_output=True, text=True)
    if made.returncode != 0:
        print(f"full disk: skipped, a tmpfs cannot be mounted here ({made.stderr.strip()})")
        return
    database = os.path.join(mount, "analyses.db")
    try:
        accepted, refused, ready = [], 0, None
        with Server("--database", database) as server:
            for i in range(300):
                if i == 20:
                    fill(os.path.join(mount, "filler"))
                body = {"kind": "rolling", "input": {"radius": f"{20 + i * 0.01:.2f} nm"}}
                status, payload, _ = request(server.port, "POST", "/v1/jobs", body)
                if status == 202:
                    accepted.append(json.loads(payload)["id"])
                else:
                    refused += status == 503
            ready = json.loads(request(server.port, "GET", "/readyz")[1])
            os.remove(os.path.join(mount, "filler"))
            for job in accepted:
                finished(server.port, job)
            server.proc.terminate()
            server.proc.wait(timeout=60)
        with Server("--database", database) as server:
            kept = sum(finished(server.port, job).get("status") == "succeeded" for job in accepted)
        print(f"full disk: {len(accepted)} accepted, {refused} refused (503); /readyz "
              f"{ready['status']}: {ready['reasons'][:1]}; after a restart with room, "
              f"{kept} of {len(accepted)} accepted jobs read succeeded, lost {len(accepted) - kept}:")
    finally:
        subprocess.run(["umount", mount], check=False)
        os.rmdir(mount)


if __name__ == "__main__":
    main()
