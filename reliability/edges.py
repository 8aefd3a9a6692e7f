"""Edges of the request path, each with its figure: a body that declares 64 MiB and sends
1 MiB (how long until the answer), 20,000 requests with invented methods (how many metric
series and how large /metrics gets), a sweep whose list lengths multiply past 2^64 with a
20 MB body limit (whether the server survives), and a client's request id written into a
text log (whether it can forge a field). Usage: reliability/edges.py"""

import json
import socket
import time

from common import Server, request

with Server("--body-limit", "20000000", "--log-format", "text") as server:
    port = server.port

    # A body declared 64 MiB, 1 MiB of it sent.
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(b"POST /v1/rolling HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
              b"Content-Length: 67108864\r\n\r\n" + b" " * (1 << 20))
    start = time.perf_counter()
    s.settimeout(120)
    head = s.recv(64).decode(errors="replace").split("\r\n")[0]
    print(f"64 MiB declared, 1 MiB sent: {head!r} after {time.perf_counter() - start:.2f} s")
    s.close()

    # Invented methods.
    for i in range(20000):
        c = socket.create_connection(("127.0.0.1", port))
        c.sendall(f"INVENTED{i} /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n".encode())
        c.recv(1024)
        c.close()
    metrics = request(port, "GET", "/metrics")[1].decode()
    series = sum(1 for line in metrics.splitlines() if line.startswith("http_requests_total{"))
    print(f"20,000 invented methods: {series} http_requests_total series, /metrics {len(metrics) / 1e6:.2f} MB")

    # Lists of 2^22, 2^21 and 2^21 values: their product wraps a 64-bit count to 0.
    numbers = lambda n: "[" + ",".join(["1"] * n) + "]"
    body = ('{"vary": {"radius": %s, "load": %s, "velocity": %s}}'
            % (numbers(1 << 22), numbers(1 << 21), numbers(1 << 21))).encode()
    try:
        status, payload, elapsed = request(port, "POST", "/v1/sweeps", body, timeout=300)
        detail = json.loads(payload).get("detail", "")[:90] if payload else ""
        print(f"sweep of 2^22 x 2^21 x 2^21 points ({len(body) / 1e6:.0f} MB): {status} after "
              f"{elapsed:.1f} s: {detail}")
    except OSError as e:
        print(f"sweep of 2^22 x 2^21 x 2^21 points: no answer ({type(e).__name__})")
    time.sleep(1)
    print(f"server alive after it: {server.proc.poll() is None}")
