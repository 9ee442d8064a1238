#!/usr/bin/env bash
# The project's main job (README): a walk, end to end, on the default robot.
#
# Builds the binaries, then lets `walkctl demo` start `walkd` and `walk-sim`, generate and
# post-process a stance sequence, submit it, watch it to the end and shut everything down.
# Extra arguments go to `walkctl demo` (e.g. `--robot jvrc1 --distance 2 --json`).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --workspace --bins
exec target/release/walkctl demo "$@"
