#!/usr/bin/env bash
# Generates a Python client from openapi/openapi.json with openapi-python-client (PyPI),
# checks that it has every operation of the spec, and calls the service through it: the
# spec is complete enough for a generated client to work.
set -euo pipefail
cd "$(dirname "$0")/.."
# In the virtual environment of reliability/venv.sh unless it is on PATH already; the
# generated client is run by the python3 first on PATH, which has its dependencies (httpx,
# attrs, python-dateutil) when it is the environment's.
. reliability/venv.sh
python_tool openapi-python-client "$OPENAPI_PYTHON_CLIENT"
. reliability/binary.sh
work=$(mktemp -d)
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
"$bin" serve --bind "127.0.0.1:$port" --log-format text --database "$work/thirdbody.db" >"$work/log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null; wait $server 2>/dev/null || true; rm -rf "$work"' EXIT
(cd "$work" && openapi-python-client generate --path "$OLDPWD/openapi/openapi.json" \
  --meta none --output-path thirdbody_client --fail-on-warning)
await_server "$server" "$port" "$work/log"
PYTHONPATH="$work" python3 - "$port" <<'PY'
import json, pathlib, sys
import thirdbody_client
from thirdbody_client import Client
from thirdbody_client.api.solve import solve_rolling, solve_sweep
from thirdbody_client.api.jobs import submit_job, get_job
from thirdbody_client.models import RollingInput, Envelope

spec = json.loads(pathlib.Path("openapi/openapi.json").read_text())
operations = {op["operationId"] for path in spec["paths"].values() for op in path.values()}
package = pathlib.Path(thirdbody_client.__file__).parent / "api"
generated = {p.stem for p in package.rglob("*.py") if p.stem != "__init__"}
missing = operations - generated
assert not missing, f"operations missing from the generated client: {sorted(missing)}"

client = Client(base_url=f"http://127.0.0.1:{sys.argv[1]}")
answer = solve_rolling.sync(client=client, body=RollingInput.from_dict({"load": "1 nN"}))
mu = answer.friction_coefficient
assert abs(mu - 0.09470) < 5e-6, mu
sweep = solve_sweep.sync_detailed(client=client, body=thirdbody_client.models.SweepInput.from_dict(
    {"vary": {"load": ["1 nN", "1.2 nN"]}}))
assert sweep.status_code == 200, sweep
accepted = submit_job.sync(client=client, body=Envelope.from_dict({"kind": "rolling"}))
job = get_job.sync(client=client, id=accepted.id)
print(f"{len(operations)} operations generated; rolling mu = {mu:.5f}; job {job.id}: {job.status}")
PY
