"""Slowloris: 1,100 connections that send a request's headers a byte every 5 s, against a
server whose open files are limited to 1,024; meanwhile a separate client asks /healthz
every 100 ms. Prints the /healthz latencies (and failures), and how long the server let the
slow connections hang. Usage: reliability/slowloris.py [seconds]"""

import resource
import socket
import sys
import threading
import time

from common import Server, latency_line, probe_health, run_for

SECONDS = float(sys.argv[1]) if len(sys.argv) > 1 else 40
SLOW = 1100


def limit_files():
    resource.setrlimit(resource.RLIMIT_NOFILE, (1024, 1024))


soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
resource.setrlimit(resource.RLIMIT_NOFILE, (max(soft, min(hard, 8192)), hard))
stop = threading.Event()
health, failures, held = [], [], []

with Server(preexec=limit_files) as server:
    port = server.port

    def slow_client():
        sockets = []
        for _ in range(SLOW):
            try:
                s = socket.create_connection(("127.0.0.1", port), timeout=5)
                s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
                sockets.append((s, time.time()))
            except OSError:
                pass
        while not stop.is_set() and sockets:
            time.sleep(5)
            alive = []
            for s, opened in sockets:
                try:
                    s.sendall(b"X")
                    s.setblocking(False)
                    try:
                        if s.recv(1) == b"":
                            raise OSError("closed")
                    except BlockingIOError:
                        pass
                    s.setblocking(True)
                    alive.append((s, opened))
                except OSError:
                    held.append(time.time() - opened)
                    s.close()
            sockets = alive
        for s, opened in sockets:
            held.append(time.time() - opened)
            s.close()

    threads = [
        threading.Thread(target=slow_client),
        threading.Thread(target=probe_health, args=(port, stop, health, failures)),
    ]
    run_for(SECONDS, threads, stop)
    held.sort()
    median = held[len(held) // 2] if held else float("nan")
    print(f"slowloris: {SLOW} slow connections, server limited to 1024 files, {SECONDS:.0f} s")
    why = f": {', '.join(sorted(set(failures)))}" if failures else ""
    print(latency_line("/healthz", health) + f", {len(failures)} failed (5 s timeout){why}")
    print(f"slow connections held: median {median:.0f} s, longest {max(held or [0]):.0f} s")
