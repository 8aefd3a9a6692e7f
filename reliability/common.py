"""What the reliability scripts share: start a `thirdbody serve` on a free loopback port,
send requests with the standard library only, sample the server's memory, and summarise
latencies. Every script takes the binary in THIRDBODY_BIN (default: the release build), so
the same measurement runs against any build (RELIABILITY.md compares before and after)."""

import hashlib
import http.client
import json
import os
import shutil
import socket
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.environ.get("THIRDBODY_BIN", os.path.join(ROOT, "target", "release", "thirdbody"))
# With THIRDBODY_RELIABILITY_KEYS=1 (`run.sh --keys`), every server requires an API key
# (`--anonymous none`) and every client presents it, the hostile ones too: the figures then
# include the access rules on every request.
KEYED = os.environ.get("THIRDBODY_RELIABILITY_KEYS") == "1"
KEY = "tb_reliability-key-of-the-measurements-0001"
KEYS = json.dumps({"keys": [{
    "name": "reliability",
    "sha256": hashlib.sha256(KEY.encode()).hexdigest(),
    "scopes": ["submit", "read", "metrics"],
}]})


def key_headers():
    """The headers that present the key, when the servers require one."""
    return {"x-api-key": KEY} if KEYED else {}


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def supports(flag):
    """Whether this build's `serve` has `flag` (older builds lack the newer limits)."""
    out = subprocess.run([BIN, "serve", "--help"], capture_output=True, text=True).stdout
    return flag in out


class Server:
    """A `thirdbody serve` on a loopback port, stopped when the `with` block ends."""

    def __init__(self, *flags, preexec=None):
        self.port = free_port()
        self.log = open(os.devnull, "w")
        # Its database of saved analyses in a directory of its own (servers run side by side,
        # and a database file is one process's), for builds that keep one.
        self.data = tempfile.mkdtemp(prefix="thirdbody-reliability-")
        if "--database" not in flags and supports("--database"):
            flags = (*flags, "--database", os.path.join(self.data, "thirdbody.db"))
        if KEYED:
            flags = (*flags, "--api-keys", KEYS, "--anonymous", "none")
        self.proc = subprocess.Popen(
            [BIN, "serve", "--bind", f"127.0.0.1:{self.port}", *flags],
            stdout=self.log,
            stderr=self.log,
            env={**os.environ, "RUST_LOG": "warn"},
            preexec_fn=preexec,
        )
        deadline = time.time() + 20
        while time.time() < deadline:
            try:
                if request(self.port, "GET", "/healthz", timeout=1)[0] == 200:
                    return
            except OSError:
                time.sleep(0.05)
        raise RuntimeError("the server did not start")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        self.log.close()
        shutil.rmtree(self.data, ignore_errors=True)

    def rss_mib(self):
        """Resident memory of the server process (MiB)."""
        with open(f"/proc/{self.proc.pid}/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024
        return float("nan")


def request(port, method, path, body=None, headers=None, timeout=30):
    """One request on a new connection: (status, body bytes, seconds)."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    data = body if isinstance(body, (bytes, type(None))) else json.dumps(body).encode()
    hdrs = {"content-type": "application/json"} if data is not None else {}
    hdrs.update(key_headers())
    hdrs.update(headers or {})
    start = time.perf_counter()
    try:
        conn.request(method, path, body=data, headers=hdrs)
        response = conn.getresponse()
        payload = response.read()
        return response.status, payload, time.perf_counter() - start
    finally:
        conn.close()


def percentile(values, p):
    if not values:
        return float("nan")
    ordered = sorted(values)
    index = min(len(ordered) - 1, max(0, round(p / 100 * (len(ordered) - 1))))
    return ordered[index]


def latency_line(name, seconds):
    ms = [s * 1000 for s in seconds]
    return (
        f"{name}: {len(ms)} requests, p50 {percentile(ms, 50):.1f} ms, "
        f"p99 {percentile(ms, 99):.1f} ms, max {max(ms) if ms else float('nan'):.1f} ms"
    )


def run_for(seconds, threads, stop, sample=None, every=1.0):
    """Starts `threads`, lets them run `seconds` (calling `sample` every `every` seconds if
    given, and returning what it gave), then sets `stop` and waits for them to end."""
    for t in threads:
        t.start()
    samples = []
    end = time.time() + seconds
    while time.time() < end:
        time.sleep(every if sample else max(0.0, end - time.time()))
        if sample:
            samples.append(sample())
    stop.set()
    for t in threads:
        t.join()
    return samples


def probe_health(port, stop, latencies, failures, every=0.1):
    """Asks /healthz every `every` seconds on a new connection until `stop` is set, adding
    each answer's seconds to `latencies` and each failure's error name to `failures`."""
    while not stop.is_set():
        try:
            latencies.append(request(port, "GET", "/healthz", timeout=5)[2])
        except OSError as e:
            failures.append(type(e).__name__)
        time.sleep(every)
