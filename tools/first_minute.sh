#!/usr/bin/env bash
# A new user's path, timed step by step on a clean state: clone -> tools/setup.sh -> cargo build
# --release -> the README's first command for each scene -> the test suite, with empty Cargo
# target, SPIR-V and Mesa shader caches (fresh folders; the user's own caches are not touched).
# Prints one line per step (wall-clock seconds) and the render's `start-up:` line, and writes
# them to $OUT/first_minute.txt. Run it on an idle machine: other jobs inflate every figure.
#
# Usage: tools/first_minute.sh [REPO] [SCENE...]
#   REPO    what to clone (default: this checkout; a URL works too)
#   SCENE   scenes to render, relative to the clone (default: scenes/cornell.gltf
#           scenes/cornell-glossy.gltf); each is rendered with its own empty caches
# Environment: OUT (default: a new temporary folder), SKIP_SETUP=1 (no tools/setup.sh, e.g.
# without root), SKIP_TESTS=1 (stop after the renders), REFERENCE_SPP=N (also path-trace a
# reference of each scene's view with N spp and print the render's relMSE against it; needs
# python3 with numpy and OpenEXR, as tools/relmse_split.py does).
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
repo="${1:-$here}"
shift || true
scenes=("$@")
[ "${#scenes[@]}" -gt 0 ] || scenes=(scenes/cornell.gltf scenes/cornell-glossy.gltf)
OUT="${OUT:-$(mktemp -d)}"
mkdir -p "$OUT"
log="$OUT/first_minute.txt"
: >"$log"

say() { echo "$*" | tee -a "$log"; }
now() { date +%s.%N; }
# Runs "$@" and prints how long it took under the name $1 (the rest is the command).
step() {
  local name="$1"
  shift
  local t0
  t0="$(now)"
  "$@" >"$OUT/$name.log" 2>&1 || { say "$name: FAILED (see $OUT/$name.log)"; exit 1; }
  say "$(printf '%-28s %8.1f s' "$name" "$(echo "$(now) - $t0" | bc)")"
}

say "first_minute: $(date -u +%Y-%m-%dT%H:%MZ) on $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
clone="$OUT/restir-pt"
step clone git clone --quiet "$repo" "$clone"
cd "$clone"
say "commit $(git rev-parse --short HEAD)"
if [ "${SKIP_SETUP:-0}" != 1 ]; then
  step setup bash tools/setup.sh
fi
export CARGO_TARGET_DIR="$OUT/target"
step build cargo build --release
bin="$CARGO_TARGET_DIR/release/restir-pt"

for scene in "${scenes[@]}"; do
  name="$(basename "$scene" .gltf)"
  export MESA_SHADER_CACHE_DIR RESTIR_PT_SPIRV_CACHE
  MESA_SHADER_CACHE_DIR="$(mktemp -d)"
  RESTIR_PT_SPIRV_CACHE="$(mktemp -d)"
  step "render $name (cold)" "$bin" render "$scene" --out "$OUT/$name.exr"
  say "  $(grep '^start-up:' "$OUT/render $name (cold).log")"
  say "  $(grep ' frames, ' "$OUT/render $name (cold).log" || true)"
  step "render $name (warm caches)" "$bin" render "$scene" --out "$OUT/$name-warm.exr"
  say "  $(grep '^start-up:' "$OUT/render $name (warm caches).log")"
  if [ -n "${REFERENCE_SPP:-}" ]; then
    step "reference $name" "$bin" reference "$scene" --spp "$REFERENCE_SPP" --out "$OUT/$name-ref.exr"
    say "  relMSE against the reference: $(python3 tools/relmse_split.py "$OUT/$name-ref.exr" "$OUT/$name.exr" | tail -n 1)"
  fi
done
unset MESA_SHADER_CACHE_DIR RESTIR_PT_SPIRV_CACHE

if [ "${SKIP_TESTS:-0}" != 1 ]; then
  step "test suite" cargo test --release
fi
say "logs and images: $OUT"
