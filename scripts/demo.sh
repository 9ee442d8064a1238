#!/usr/bin/env bash
# The project's main job (README): a walk, end to end, on the default robot, under real physics.
#
# Sets up the pinned MuJoCo library, builds the binaries, then lets `walkctl demo` start `walkd`
# and `walk-sim --physics mujoco` in real time, generate and post-process a 1 m stance sequence for
# ARMAR-4, submit it for the dynamic gait, watch it to the end, record it with an observer (MCAP)
# and plot it (Fig. 6), and shut everything down. It ends by printing where the recording and the
# plot are and how to open them. Extra arguments go to `walkctl demo` and win over these defaults
# (e.g. `--gait static` for the source paper's quasi-static gait, `--physics kinematic`,
# `--robot jvrc1 --distance 2 --json`, `--record DIR`, `--plots DIR`).
set -euo pipefail
cd "$(dirname "$0")/.."

mujoco_env="$(scripts/setup-mujoco.sh)"
eval "$mujoco_env"

cargo build --release --workspace --bins --features sim-adapter/mujoco,sim-adapter/render

readonly OUT="target/demo"
defaults=()
has() { local flag="$1"; shift; for arg in "$@"; do [[ "$arg" == "$flag" || "$arg" == "$flag="* ]] && return 0; done; return 1; }
has --physics "$@" || defaults+=(--physics mujoco)
has --gait "$@" || defaults+=(--gait dynamic)
has --record "$@" || defaults+=(--record "$OUT")
has --plots "$@" || defaults+=(--plots "$OUT")
exec target/release/walkctl demo "${defaults[@]}" "$@"
