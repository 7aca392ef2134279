#!/usr/bin/env bash
# Installs the Debian packages the project needs, only those missing.
# Idempotent and silent when everything is present; uses sudo when not root.
set -euo pipefail

packages=(
  blender cmake g++ make pkg-config patchelf
  python3 python3-dev python3-venv python3-numpy python3-matplotlib
  pybind11-dev libglm-dev libopenimageio-dev libembree-dev libtbb-dev
  libgtest-dev libbenchmark-dev
  xvfb libgl1-mesa-dri xdotool  # the interactive (modal, Esc) tests: Blender in a virtual display, real key presses
  clang-format-16       # tests/native/test_format.py: the C++ follows .clang-format
)

# `make fuzz` (tools/fuzz.py) builds its libFuzzer harnesses and an instrumented
# module with clang 16 (Debian 12's clang 14 lacks _Float16 on x86-64) and its
# compiler-rt (libFuzzer, the sanitizers): only asked for by `install-deps.sh fuzz`.
if [[ "${1:-}" == fuzz ]]; then
  packages+=(clang-16 libclang-rt-16-dev)
fi

# `make test-platforms` (tools/cross_build.py, tests/platforms) runs the Windows modules
# under Wine (Debian's Wine 8: wine, wine64) and reads the macOS modules' Mach-O with
# LLVM's tools (llvm-objdump-16, llvm-nm-16): only asked for by `install-deps.sh platforms`.
if [[ "${1:-}" == platforms ]]; then
  packages+=(wine wine64 llvm-16)
fi

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
