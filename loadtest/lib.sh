# shellcheck shell=bash
# What the load scripts share (sourced, not run).

# Waits until the service at the base URL $1 answers /healthz: $2 tries (default 100),
# $3 s apart (default 0.1). A server that never answers is left to the caller's requests
# to report.
wait_ready() {
  for _ in $(seq "${2:-100}"); do
    curl -sf "$1/healthz" >/dev/null && return 0
    sleep "${3:-0.1}"
  done
}

# The CPU time (clock ticks, user + system) process $1 has used (the fields after the
# process's name, which may hold spaces).
ticks() {
  sed 's/.*) //' "/proc/$1/stat" | awk '{print $12 + $13}'
}
