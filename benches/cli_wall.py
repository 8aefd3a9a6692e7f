"""Wall time of one `thirdbody solve` process, start to exit, against `/bin/true` started the
same way (issue 12: "a CLI single job ≤ 2 ms wall, process included").

    python3 benches/cli_wall.py [JOB.json] [RUNS]     (defaults: examples/rolling.json, 300)

The two commands alternate, so that both see the same machine; prints the median and the
10th and 90th percentiles. Not part of CI: a yardstick for BENCHMARKS.md.
"""

import subprocess
import sys
import time

job = sys.argv[1] if len(sys.argv) > 1 else "examples/rolling.json"
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 300
commands = {
    f"thirdbody solve {job}": ["target/release/thirdbody", "solve", job],
    "/bin/true": ["/bin/true"],
}
times = {name: [] for name in commands}
for _ in range(runs):
    for name, command in commands.items():
        start = time.perf_counter()
        subprocess.run(command, stdout=subprocess.DEVNULL, check=True)
        times[name].append(time.perf_counter() - start)
for name, samples in times.items():
    samples.sort()
    p = lambda q: samples[int(q * (len(samples) - 1))] * 1e3
    print(f"{name}: median {p(0.5):.2f} ms (p10 {p(0.1):.2f}, p90 {p(0.9):.2f})")
