#!/usr/bin/env bash
# Fetches and places the pinned MuJoCo library for the `mujoco` feature of sim-adapter.
#
# mujoco-rs 7.0.0+mj-3.17.0 links against exactly MuJoCo 3.17.0 (it checks the version at run
# time). The library is taken from the PyPI wheel `mujoco==3.17.0` (the only registry this project
# can reach that ships it), verified against pinned sha256 sums and placed in
# `.deps/mujoco/lib/` (gitignored) as `libmujoco.so.3.17.0` plus the `libmujoco.so` link the
# build needs. Idempotent: a verified library already in place is kept.
#
# Usage:  eval "$(scripts/setup-mujoco.sh)"
# stdout: the environment the build needs (one `export` line); progress goes to stderr.
# The sim-adapter build script bakes that directory into its binaries' rpath, so nothing is
# needed at run time.
set -euo pipefail
cd "$(dirname "$0")/.."

readonly MUJOCO_VERSION="3.17.0"
# One fixed wheel (CPython 3.11, manylinux_2_28 x86_64), whatever the local Python is, so the
# pinned sums hold on every machine. Only the C library inside it is used.
readonly WHEEL="mujoco-${MUJOCO_VERSION}-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl"
readonly WHEEL_SHA256="d66928d86a2d1b601bbaa4dc11db50214d17d5301bb8afd84721313b67ff0874"
readonly LIB="libmujoco.so.${MUJOCO_VERSION}"
readonly LIB_SHA256="23496b023ee80fb61ab71167e94bc649f9941710fde96b18bb8204fb332523ad"

readonly DEPS_DIR="$PWD/.deps/mujoco"
readonly LIB_DIR="$DEPS_DIR/lib"

log() { echo "setup-mujoco: $*" >&2; }
fail() { log "error: $*"; exit 1; }

sha256_of() { sha256sum "$1" | cut -d' ' -f1; }

if [[ "$(uname -s)-$(uname -m)" != "Linux-x86_64" ]]; then
    fail "only Linux x86_64 is supported (this is $(uname -s) $(uname -m))"
fi

if [[ -f "$LIB_DIR/$LIB" && "$(sha256_of "$LIB_DIR/$LIB")" == "$LIB_SHA256" ]]; then
    log "MuJoCo $MUJOCO_VERSION already in $LIB_DIR"
else
    command -v python3 >/dev/null || fail "python3 (with pip) is needed to fetch the mujoco wheel"
    mkdir -p "$DEPS_DIR/wheel" "$LIB_DIR"
    if [[ ! -f "$DEPS_DIR/wheel/$WHEEL" || "$(sha256_of "$DEPS_DIR/wheel/$WHEEL")" != "$WHEEL_SHA256" ]]; then
        log "downloading the mujoco==$MUJOCO_VERSION wheel"
        rm -f "$DEPS_DIR/wheel/$WHEEL"
        python3 -m pip download --quiet --no-deps --only-binary=:all: \
            --implementation cp --python-version 3.11 --platform manylinux_2_28_x86_64 \
            --dest "$DEPS_DIR/wheel" "mujoco==$MUJOCO_VERSION" >&2 \
            || fail "pip could not download mujoco==$MUJOCO_VERSION"
    fi
    [[ -f "$DEPS_DIR/wheel/$WHEEL" ]] || fail "pip did not produce $WHEEL"
    actual="$(sha256_of "$DEPS_DIR/wheel/$WHEEL")"
    [[ "$actual" == "$WHEEL_SHA256" ]] \
        || fail "$WHEEL has sha256 $actual, expected $WHEEL_SHA256"
    log "extracting $LIB"
    python3 - "$DEPS_DIR/wheel/$WHEEL" "mujoco/$LIB" "$LIB_DIR/$LIB.tmp" <<'PY'
import shutil, sys, zipfile
wheel, member, dest = sys.argv[1:]
with zipfile.ZipFile(wheel) as zf, zf.open(member) as src, open(dest, "wb") as dst:
    shutil.copyfileobj(src, dst)
PY
    actual="$(sha256_of "$LIB_DIR/$LIB.tmp")"
    [[ "$actual" == "$LIB_SHA256" ]] || fail "$LIB has sha256 $actual, expected $LIB_SHA256"
    chmod 0755 "$LIB_DIR/$LIB.tmp"
    mv -f "$LIB_DIR/$LIB.tmp" "$LIB_DIR/$LIB"
    rm -rf "$DEPS_DIR/wheel"
    log "MuJoCo $MUJOCO_VERSION placed in $LIB_DIR"
fi
ln -sfn "$LIB" "$LIB_DIR/libmujoco.so"

echo "export MUJOCO_DYNAMIC_LINK_DIR=$LIB_DIR"
