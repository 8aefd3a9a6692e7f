# shellcheck shell=bash
# Sourced by the reliability scripts: sets `bin` to the binary they run, THIRDBODY_BIN when
# given (CI passes the one `cargo test` built, saving a second build of everything), else
# the release build, built now if it is out of date.
if [ -n "${THIRDBODY_BIN:-}" ]; then
  bin="$THIRDBODY_BIN"
else
  cargo build --release --locked --quiet --bin thirdbody
  bin=target/release/thirdbody
fi
export THIRDBODY_BIN="$bin"

# `await_server PID PORT LOG`: waits until the server PID answers /healthz on PORT, however
# loaded the machine (up to 120 s); fails with the end of its LOG if it exits first or never
# answers.
await_server() {
  local pid=$1 port=$2 log=$3 tries
  for ((tries = 0; tries < 1200; tries++)); do
    curl -sf "http://127.0.0.1:$port/healthz" >/dev/null && return 0
    if ! kill -0 "$pid" 2>/dev/null; then
      echo "thirdbody serve exited before it answered on port $port; its log ends:" >&2
      tail -n 30 "$log" >&2
      return 1
    fi
    sleep 0.1
  done
  echo "thirdbody serve did not answer /healthz on port $port in 120 s; its log ends:" >&2
  tail -n 30 "$log" >&2
  return 1
}
