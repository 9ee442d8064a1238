#!/usr/bin/env bash
# The project's test command (README): builds everything it needs, then runs every test.
#
# The end-to-end tests start the real `walkd`, `walk-sim` and `walkctl` processes, which live in
# other packages than the tests, so the binaries are built first. Everything is built with
# `--release` so one build of the dependency set serves the demo, the tests and the benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --workspace --bins
cargo test --release --workspace "$@"
