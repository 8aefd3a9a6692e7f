#!/usr/bin/env bash
# Fuzzes job parsing, validation and solving (fuzz/fuzz_targets/job.rs) with libFuzzer via
# cargo-fuzz for a fixed time, from the committed corpus (fuzz/corpus/job). cargo-fuzz needs
# nightly flags: RUSTC_BOOTSTRAP lets the stable toolchain take them. Fails on any crash.
# Usage: reliability/fuzz.sh [seconds]
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds="${1:-60}"
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked --version '^0.13'
export RUSTC_BOOTSTRAP=1
cargo fuzz build job -O -s none
cargo fuzz run job -O -s none -- -max_total_time="$seconds" -max_len=4096 -print_final_stats=1
