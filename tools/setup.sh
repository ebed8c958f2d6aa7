#!/usr/bin/env bash
# Installs every system package restir-pt needs on Debian/Ubuntu: lavapipe (Mesa's CPU Vulkan
# driver), the Vulkan loader and validation layer, and the static glslang/shaderc/SPIRV-Tools
# archives that .cargo/config.toml links, and the font the charts of `compare` and `stability` use. Idempotent and non-interactive; runs as root or via sudo.
set -euo pipefail

packages=(
  mesa-vulkan-drivers libvulkan1 vulkan-validationlayers vulkan-tools
  glslang-tools glslang-dev spirv-tools libshaderc-dev
  build-essential pkg-config
  fonts-dejavu-core
)

if [ "$(id -u)" -eq 0 ]; then
  sudo=()
else
  command -v sudo >/dev/null || { echo "tools/setup.sh: needs root or sudo to install packages" >&2; exit 1; }
  sudo=(sudo)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ "${#missing[@]}" -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Ray (PyPI) runs tools/cluster/ray_sweep.py; the suite's Ray test runs where python3 imports it
# and skips with a note otherwise. About 25 s and 285 MB (ray 2.60, measured 2026-11-30).
if command -v python3 >/dev/null; then
  if ! python3 -c "import ray" 2>/dev/null; then
    python3 -m pip install --quiet --disable-pip-version-check ray ||
      echo "tools/setup.sh: warning: pip could not install ray; the Ray test will skip (or set RESTIR_PT_PYTHON to a Python with ray)" >&2
  fi
else
  echo "tools/setup.sh: warning: no python3; tools/cluster/ray_sweep.py and its test need Python 3 with ray" >&2
fi

command -v cargo >/dev/null || { echo "tools/setup.sh: cargo not found; install Rust (rustup) first" >&2; exit 1; }
# cargo-nextest runs the suite one process per test (README, .ci/run); built from crates.io
# where missing (several minutes on 2 cores).
if ! cargo nextest --version >/dev/null 2>&1; then
  cargo install cargo-nextest --locked
fi
echo "tools/setup.sh: system packages present (${#packages[@]} checked, ${#missing[@]} installed)"
