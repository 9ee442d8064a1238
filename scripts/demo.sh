#!/usr/bin/env bash
# The project's main job (README): a walk, end to end, on the default robot.
#
# Sets up the pinned MuJoCo library, builds the binaries, then lets `walkctl demo` start `walkd`
# and `walk-sim`, generate and post-process a stance sequence, submit it, watch it to the end and
# shut everything down. Extra arguments go to `walkctl demo` (e.g. `--robot jvrc1 --distance 2
# --json`, or `--physics mujoco`).
set -euo pipefail
cd "$(dirname "$0")/.."

mujoco_env="$(scripts/setup-mujoco.sh)"
eval "$mujoco_env"

cargo build --release --workspace --bins --features sim-adapter/mujoco
exec target/release/walkctl demo "$@"
