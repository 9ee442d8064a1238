#!/usr/bin/env bash
# Fetches the climbing demonstrations of `holosoma-retargeting` 0.1.0 that are not vendored
# (sequences 0, 2, 3 and 4; sequence 1 is in data/demonstrations/holosoma-climb) into a
# demonstration folder with its demo.toml, for `walkctl learn --demos DIR`.
#
# Usage:  scripts/fetch-demos.sh [DEST]   (default: target/demonstrations/holosoma-climb-extra)
# Needs pip (PyPI). The wheel and every extracted file are checked against pinned sha256 sums.
set -euo pipefail
cd "$(dirname "$0")/.."

readonly DEST="${1:-target/demonstrations/holosoma-climb-extra}"
readonly WHEEL="holosoma_retargeting-0.1.0-py3-none-any.whl"
readonly WHEEL_SHA256="3dcdcc06c6705c091478808024298dfcc684d9eb49e890cc6b11fc03fa246cb4"
# sha256, path in the wheel, and the capture axis the subject walks along (`forward`, checked
# when the trial is loaded: the direction of the pelvis's farthest point from its start).
readonly FILES=(
  "0d10253c34f26148c40e96261033b7e5955bcd5d784b76a02be8847aa2b75d8d mocap_climb_seq_0/mocap_climb_seq_0_joint_positions_f900-3700.npy -y"
  "fb33fb51393fc1408876f91ef2dfd2a0e1944b148c54a275f9a5a0965dca253a mocap_climb_seq_2/mocap_climb_seq_2_joint_positions_f100-3110.npy -x"
  "6c9f16cd72bd8e87b8b4d69b3d11370d56f5160af2882215baf45464d6bd0843 mocap_climb_seq_3/mocap_climb_seq_3_joint_positions_f200-2600.npy -x"
  "503c423d5aeaff9805316a62c47ec1dd99f8cb5668fdc041510398e29d846984 mocap_climb_seq_4/mocap_climb_seq_4_joint_positions_f0-2303.npy +y"
)

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "downloading ${WHEEL} ..." >&2
pip download --quiet --no-deps "holosoma-retargeting==0.1.0" -d "$work" >&2
echo "${WHEEL_SHA256}  ${work}/${WHEEL}" | sha256sum --check --quiet
mkdir -p "$DEST"
{
  echo "# Fetched by scripts/fetch-demos.sh from PyPI holosoma-retargeting 0.1.0 (Apache-2.0)."
} > "$DEST/demo.toml"
for entry in "${FILES[@]}"; do
  read -r sum path forward <<<"$entry"
  name="$(basename "$path")"
  unzip -p "$work/$WHEEL" "holosoma_retargeting/demo_data/climb/$path" > "$DEST/$name"
  echo "${sum}  ${DEST}/${name}" | sha256sum --check --quiet
  printf '\n[[trial]]\nfile = "%s"\nformat = "npy-mocap53"\nforward = "%s"\nup = "+z"\nrate = 120.0\n' "$name" "$forward" >> "$DEST/demo.toml"
  echo "  ${DEST}/${name}" >&2
done
echo "done: walkctl learn --demos ... ${DEST}" >&2
