"""A large checks suite: POST /v1/checks with about 930 kB of checks (7,300 rolling jobs,
each with one expectation), just under the default 1 MiB body limit. Prints the answer's
status and time and the server's RSS before and after. Usage: reliability/checks_memory.py"""

import json

from common import Server, request

CHECKS = [
    {
        "name": f"c{i}",
        "job": {"kind": "rolling", "input": {"load": f"{1 + i / 1e5} nN"}},
        "expect": {"friction_coefficient": {"max": 1}},
    }
    for i in range(7300)
]
BODY = json.dumps({"checks": CHECKS}).encode()

with Server() as server:
    before = server.rss_mib()
    status, payload, seconds = request(server.port, "POST", "/v1/checks", BODY, timeout=120)
    print(
        f"checks suite: {len(BODY) / 1e3:.0f} kB, {len(CHECKS)} checks: status {status} in "
        f"{seconds:.1f} s, RSS {before:.0f} -> {server.rss_mib():.0f} MiB"
    )
