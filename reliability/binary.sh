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
