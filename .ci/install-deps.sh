#!/usr/bin/env bash
# Installs the Debian packages the project needs, only those missing.
# Idempotent and silent when everything is present; uses sudo when not root.
set -euo pipefail

packages=(
  blender cmake g++ make pkg-config patchelf
  python3 python3-dev python3-venv python3-numpy python3-matplotlib
  pybind11-dev libglm-dev libopenimageio-dev libembree-dev libtbb-dev
  libgtest-dev libbenchmark-dev
  xvfb libgl1-mesa-dri  # the interactive (modal, ESC) test runs Blender in a virtual display
)

# Node.js and npm run the Khronos glTF validator (tools/gltf_validator.py, which
# installs the validator itself into the build tree). Checked by command: a
# Node.js from elsewhere (NodeSource's nodejs, which includes npm) will do.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "Installing missing Debian packages: ${missing[*]}"
sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "error: not root and no sudo; install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
echo "Installed: ${missing[*]}"
