#!/usr/bin/env bash
# Installs what observing and rendering a walk need beyond the Rust build (docs/observe.md):
#
# - Debian's EGL and Mesa software-rendering packages, for MuJoCo's offscreen renderer
#   (walk-sim --snapshots, walkctl evaluate --snapshots): libegl1, libegl-mesa0, libgl1-mesa-dri;
# - with --python: the independent readers the observer tests use, from PyPI: mcap and
#   mcap-protobuf-support (the official MCAP reader and its protobuf decoder) and websockets
#   (a Foxglove WebSocket client of the tests' own).
#
# Idempotent: what is already there is kept, and nothing is fetched then. Where it cannot install
# something (not root, no apt-get, no network) it says what is missing and how to install it, and
# exits non-zero; progress goes to stderr.
#
# Usage:  scripts/setup-observe.sh [--python]
set -euo pipefail
cd "$(dirname "$0")/.."

readonly EGL_PACKAGES=(libegl1 libegl-mesa0 libgl1-mesa-dri)
# Pinned so every machine reads recordings with the same reader.
readonly PYTHON_PACKAGES=(mcap==1.6.0 mcap-protobuf-support==0.6.0 websockets==17.4)
readonly PYTHON_MODULES=(mcap mcap_protobuf websockets)

log() { echo "setup-observe: $*" >&2; }

missing_debian_packages() {
    local package
    for package in "${EGL_PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
            || echo "$package"
    done
}

install_egl() {
    command -v dpkg-query >/dev/null || {
        log "not a Debian system: install EGL with Mesa's software rasteriser (llvmpipe) for the renderer"
        return 1
    }
    local missing
    mapfile -t missing < <(missing_debian_packages)
    if ((${#missing[@]} == 0)); then
        log "EGL packages present (${EGL_PACKAGES[*]})"
        return 0
    fi
    if [[ "$(id -u)" != 0 ]] || ! command -v apt-get >/dev/null; then
        log "error: the renderer needs ${missing[*]}; install them as root: apt-get install ${missing[*]}"
        return 1
    fi
    log "installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    if ! apt-get install -y --no-install-recommends "${missing[@]}" >&2; then
        apt-get update >&2 || true
        apt-get install -y --no-install-recommends "${missing[@]}" >&2 || {
            log "error: apt-get could not install ${missing[*]} (the renderer needs them)"
            return 1
        }
    fi
}

install_python() {
    command -v python3 >/dev/null || {
        log "error: python3 (with pip) is needed for the observer tests' readers"
        return 1
    }
    if python3 -c "import $(IFS=,; echo "${PYTHON_MODULES[*]}")" 2>/dev/null; then
        log "Python readers present (${PYTHON_MODULES[*]})"
        return 0
    fi
    log "installing ${PYTHON_PACKAGES[*]} from PyPI"
    python3 -m pip install --quiet --disable-pip-version-check "${PYTHON_PACKAGES[@]}" >&2 || {
        log "error: pip could not install ${PYTHON_PACKAGES[*]}"
        return 1
    }
}

status=0
install_egl || status=1
if [[ "${1:-}" == "--python" ]]; then
    install_python || status=1
fi
exit "$status"
