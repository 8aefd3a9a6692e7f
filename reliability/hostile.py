"""Connection holders: 511 hostile connections (one short of the default --max-connections)
that try to keep the service's connections to themselves, while a prober asks /healthz
every 100 ms and a well-behaved client sends a solve every 50 ms, each on a new connection.
A closed hostile connection is opened again at once, as a persistent attacker would.

Modes:
  slow-readers  ask for a 3.3 MB answer (a cached 5,000-point sweep) with a 4 KiB receive
                buffer, and never read it
  keep-alive    send a request every 4 s on each connection, idling in between
  slow-bodies   declare a 1,000-byte body and send a byte of it every 5 s
  sse           follow a running job's events and never read them

Prints, for each mode, the /healthz latencies and failures, the well-behaved client's
successes, and how long the service let the hostile connections stay.
Usage: reliability/hostile.py MODE|all [seconds]"""

import json
import multiprocessing
import resource
import socket
import sys
import threading
import time

from common import Server, key_headers, latency_line, probe_health, request

MODES = ["slow-readers", "keep-alive", "slow-bodies", "sse"]
# The header lines that present the API key, when the servers require one (common.py).
KEY_LINES = "".join(f"{name}: {value}\r\n" for name, value in key_headers().items())
HOSTILE = 511
TCP_ESTABLISHED = 1
SWEEP = json.dumps({"vary": {"load": [f"{1 + i / 5000} nN" for i in range(5000)]}}).encode()
# A three-body sweep of a few seconds: the job the sse holders follow.
LONG_JOB = json.dumps(
    {
        "kind": "sweep",
        "input": {
            "kind": "three_body",
            "base": {"operating": {"total_load": "1 mN"}},
            "vary": {
                "total_load": [f"{1 + i / 1000} mN" for i in range(1000)],
                "velocity": [f"{v} nm/s" for v in range(10)],
            },
        },
    }
).encode()


def post(path, body, length=None):
    """A POST request's bytes: its head, declaring `length` bytes (default: the body's)."""
    length = len(body) if length is None else length
    return (
        f"POST {path} HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
        f"{KEY_LINES}Content-Length: {length}\r\n\r\n"
    ).encode() + body


class Holder:
    """One hostile connection and what it does next."""

    def __init__(self, port, mode, job):
        self.mode = mode
        self.opened = time.time()
        self.next = self.opened
        self.sock = socket.socket()
        if mode == "slow-readers":
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        self.sock.settimeout(2)
        self.sock.connect(("127.0.0.1", port))
        self.sock.setblocking(False)
        if mode == "slow-readers":
            self.send(post("/v1/sweeps", SWEEP))
        elif mode == "slow-bodies":
            self.send(post("/v1/rolling", b"", length=1000))
        elif mode == "sse":
            self.send(
                f"GET /v1/jobs/{job()}/events HTTP/1.1\r\nHost: x\r\n{KEY_LINES}"
                "Accept: text/event-stream\r\n\r\n".encode()
            )

    def send(self, data):
        try:
            self.sock.send(data)
        except BlockingIOError:
            pass

    def alive(self):
        """Whether the service still holds the connection open (read from the kernel's
        TCP state, so that a holder that never reads still learns it was closed)."""
        try:
            state = self.sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_INFO, 1)[0]
        except OSError:
            return False
        return state == TCP_ESTABLISHED

    def act(self, now):
        """What the holder does on its schedule (the readers and followers only wait)."""
        if now < self.next:
            return
        if self.mode == "keep-alive":
            self.send(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
            self.next = now + 4
            try:  # read the small answers, so that only idling holds the connection
                while self.sock.recv(65536):
                    pass
            except (BlockingIOError, OSError):
                pass
        elif self.mode == "slow-bodies":
            self.send(b" ")
            self.next = now + 5


def attacker(port, mode, job_id, stop, results):
    """Keeps HOSTILE connections open until `stop`; puts how long each was held and how
    many were opened on `results`."""
    holders, held, opened_total = [], [], 0

    def current_job():
        return job_id.value.decode() or "00000000-0000-0000-0000-000000000000"

    while not stop.is_set():
        now = time.time()
        kept = []
        for h in holders:
            if h.alive():
                kept.append(h)
            else:
                held.append(now - h.opened)
                h.sock.close()
        holders = kept
        opened = 0
        while len(holders) < HOSTILE and opened < 100:
            try:
                holders.append(Holder(port, mode, current_job))
            except OSError:
                break
            opened += 1
        opened_total += opened
        for h in holders:
            h.act(now)
        time.sleep(0.2)
    for h in holders:
        held.append(time.time() - h.opened)
        h.sock.close()
    results.put((held, opened_total))


def run(mode, seconds):
    stop = threading.Event()
    health, health_failed, solves = [], [], {"ok": 0, "failed": 0}
    with Server() as server:
        port = server.port
        if mode == "slow-readers":
            request(port, "POST", "/v1/sweeps", SWEEP, timeout=60)  # solved once, then cached
        jobs = []

        def feed_jobs():
            # Keeps a job running for the sse holders to follow.
            while not stop.is_set():
                if not jobs or not job_running(jobs[-1]):
                    status, body, _ = request(port, "POST", "/v1/jobs", LONG_JOB, timeout=10)
                    if status == 202:
                        jobs.append(json.loads(body)["id"])
                        job_id.value = jobs[-1].encode()
                time.sleep(0.5)

        def job_running(job):
            try:
                status, body, _ = request(port, "GET", f"/v1/jobs/{job}", timeout=5)
                return status == 200 and json.loads(body)["status"] in ("queued", "running")
            except OSError:
                return False

        # The attacker runs in a process of its own, so that its work does not delay the
        # prober's and the client's measurements (one interpreter lock).
        job_id = multiprocessing.Array("c", 64)
        results = multiprocessing.Queue()
        attacking = multiprocessing.Event()
        attack = multiprocessing.Process(
            target=attacker, args=(port, mode, job_id, attacking, results)
        )

        def client():
            i = 0
            while not stop.is_set():
                i += 1
                try:
                    status = request(
                        port, "POST", "/v1/rolling", {"load": f"{1 + i % 50 / 100} nN"}, timeout=5
                    )[0]
                    solves["ok" if status == 200 else "failed"] += 1
                except OSError:
                    solves["failed"] += 1
                time.sleep(0.05)

        threads = [
            threading.Thread(target=probe_health, args=(port, stop, health, health_failed)),
            threading.Thread(target=client),
        ]
        if mode == "sse":
            threads.append(threading.Thread(target=feed_jobs))
            deadline = time.time() + 10
            while not jobs and time.time() < deadline:
                time.sleep(0.1)
        attack.start()
        for t in threads:
            t.start()
        time.sleep(seconds)
        stop.set()
        attacking.set()
        held, opened = results.get()
        attack.join()
        for t in threads:
            t.join()
        alive = server.proc.poll() is None
    held.sort()
    median = held[len(held) // 2] if held else float("nan")
    total = solves["ok"] + solves["failed"]
    share = 100 * solves["ok"] / total if total else float("nan")
    print(f"hostile {mode}: {HOSTILE} connections, {seconds:.0f} s, server alive at the end: {alive}")
    why = f": {', '.join(sorted(set(health_failed)))}" if health_failed else ""
    print(latency_line("  /healthz", health) + f", {len(health_failed)} failed (5 s timeout){why}")
    print(f"  well-behaved solves: {solves['ok']} of {total} succeeded ({share:.1f} %)")
    print(
        f"  hostile connections opened {opened}, held median {median:.1f} s, "
        f"longest {max(held or [0]):.1f} s"
    )


if __name__ == "__main__":
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, 8192)), hard))
    which = sys.argv[1] if len(sys.argv) > 1 else "all"
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 30
    for mode in MODES if which == "all" else [which]:
        run(mode, seconds)
