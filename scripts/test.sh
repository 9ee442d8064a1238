#!/usr/bin/env bash
# The project's test command (README): sets up, builds everything it needs, runs every test.
#
# Set-up: the pinned MuJoCo library for the physics back-end (scripts/setup-mujoco.sh), the EGL
# packages of the renderer and the Python readers of the observer tests (scripts/setup-observe.sh). The
# end-to-end tests start the real `walkd`, `walk-sim` and `walkctl` processes, which live in
# other packages than the tests, so the binaries are built first. Everything is built with
# `--release` and the same features, so one build of the dependency set serves the demo, the
# tests and the benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."

mujoco_env="$(scripts/setup-mujoco.sh)"
eval "$mujoco_env"
# The renderer's EGL packages and the observer tests' independent readers (Python mcap,
# mcap-protobuf-support, websockets).
scripts/setup-observe.sh --python \
    || echo "test.sh: continuing; the tests that need what is missing fail and name it" >&2

cargo build --release --workspace --bins --features sim-adapter/mujoco,sim-adapter/render
# The adapter example of docs/adapter.md, run by the e2e tests.
cargo build --release -p sim-adapter --examples --features sim-adapter/mujoco
# walk-bench/mujoco: the in-process physics walk (bench/tests/physics_walk.rs fails if it is off).
cargo test --release --workspace --features sim-adapter/mujoco,sim-adapter/render,walk-bench/mujoco "$@"
