#!/usr/bin/env bash
# Fuzzes job parsing, validation and solving (fuzz/fuzz_targets/job.rs) with libFuzzer for a
# fixed time, from the committed corpus (fuzz/corpus/job). Fails on any crash.
#
# Built by cargo itself, with the flags `cargo fuzz build job -O -s none` passes (cargo-fuzz
# 0.13, src/project.rs: sanitizer-coverage instrumentation, `--cfg fuzzing`, one codegen unit,
# release with line tables, for the host's triple, into fuzz/target), and run with the
# arguments `cargo fuzz run` gives libFuzzer (its artifacts in fuzz/artifacts/job/, the
# corpus last): the same target, instrumentation, corpus and verdict, without compiling
# cargo-fuzz itself, which took minutes on a fresh machine. The flags are all stable: no
# sanitizer is asked for (`-s none`), so no nightly flag either.
# Usage: reliability/fuzz.sh [seconds]
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds="${1:-60}"
target=job
triple=$(rustc -vV | sed -n 's/^host: //p')
flags=(
  -Cpasses=sancov-module
  -Cllvm-args=-sanitizer-coverage-level=4
  -Cllvm-args=-sanitizer-coverage-inline-8bit-counters
  -Cllvm-args=-sanitizer-coverage-pc-table
  -Cllvm-args=-sanitizer-coverage-trace-compares
  --cfg fuzzing
  -Cllvm-args=-simplifycfg-branch-fold-threshold=0
)
if [[ $triple == *-linux-* ]]; then
  flags+=(-Cllvm-args=-sanitizer-coverage-stack-depth)
fi
flags+=(-Ccodegen-units=1)
# As cargo-fuzz does, the caller's RUSTFLAGS come last, so that they win.
RUSTFLAGS="${flags[*]}${RUSTFLAGS:+ $RUSTFLAGS}" cargo build --manifest-path Cargo.toml \
  --target "$triple" --release --config 'profile.release.debug="line-tables-only"' \
  --locked --bin "$target"
mkdir -p "artifacts/$target" "corpus/$target"
"${CARGO_TARGET_DIR:-target}/$triple/release/$target" -artifact_prefix="$PWD/artifacts/$target/" \
  -max_total_time="$seconds" -max_len=4096 -print_final_stats=1 "corpus/$target"
