#!/usr/bin/env bash
# Regenerates docs/results/, the figures README.md's "Results" section shows, with the commands
# the README quotes: a path-traced reference per scene and camera, then `compare` at equal GPU
# time. Each item writes results.csv, rel_mse_vs_time.png and equal_time.png to
# $DEST/<item>/ (the rest of compare's output stays in $WORK/<item>/).
#
# Usage: tools/make_results.sh [ITEM...]     (default: the README's items; hours on 2 CPU cores)
# Items: static-veach-door static-cornell-glossy motion-veach-door-8 motion-cornell-glossy-8
#        and, not in the README, motion-veach-door-16 motion-cornell-glossy-16
# Environment: RESTIR_PT (binary; default target/release/restir-pt, built if missing),
#   DEST (default docs/results), WORK (default out/make_results),
#   REF_SPP (reference samples per pixel, default 4096) and TRIALS (runs per point, default the
#   README's) to make a quick, rough run, e.g. REF_SPP=64 TRIALS=1 DEST=/tmp/r.
set -euo pipefail
cd "$(dirname "$0")/.."

DEST=${DEST:-docs/results}
WORK=${WORK:-out/make_results}
REF_SPP=${REF_SPP:-4096}
if [[ -z ${RESTIR_PT:-} ]]; then
    RESTIR_PT=target/release/restir-pt
    [[ -x $RESTIR_PT ]] || cargo build --release
fi

ALL=(static-veach-door static-cornell-glossy motion-veach-door-8 motion-cornell-glossy-8)

# A reference of SCENE from CAMERA at SIZE×SIZE, made once per WORK folder.
reference() {
    local scene=$1 camera=$2 size=$3 out=$4
    [[ -f $out ]] && return 0
    "$RESTIR_PT" reference "scenes/$scene.gltf" --width "$size" --height "$size" --camera "$camera" \
        --spp "$REF_SPP" --out "$out"
}

# Equal time with an unmoved camera: frame 16, 64×64, temporal reuse only (README "A static camera").
static() {
    local scene=$1 out=$2 ref="$WORK/$1-64-camera0-ref.exr"
    reference "$scene" 0 64 "$ref"
    "$RESTIR_PT" compare "scenes/$scene.gltf" --reference "$ref" --spatial 0 \
        --methods pt,restir:reconnection --budgets-ms 20,40,80,160 --trials "${TRIALS:-12}" --out-dir "$out"
}

# Equal time with the camera moving along the scene's camera path for FRAMES frames, 128×128;
# the last frame's camera is 7 after 8 frames and 1 after 16 (README "A moving camera").
motion() {
    local scene=$1 frames=$2 out=$3 camera
    case $frames in 8) camera=7 ;; 16) camera=1 ;; *) echo "no camera for $frames frames" >&2; return 1 ;; esac
    local ref="$WORK/$scene-128-camera$camera-ref.exr"
    reference "$scene" "$camera" 128 "$ref"
    "$RESTIR_PT" compare "scenes/$scene.gltf" --reference "$ref" --frames "$frames" --camera-path \
        --methods pt,restir,restir@s0 --trials "${TRIALS:-8}" --out-dir "$out"
}

items=("$@")
[[ ${#items[@]} -gt 0 ]] || items=("${ALL[@]}")
mkdir -p "$WORK"
for item in "${items[@]}"; do
    out="$WORK/$item"
    case $item in
        static-veach-door) static veach-door "$out" ;;
        static-cornell-glossy) static cornell-glossy "$out" ;;
        motion-veach-door-8) motion veach-door 8 "$out" ;;
        motion-veach-door-16) motion veach-door 16 "$out" ;;
        motion-cornell-glossy-8) motion cornell-glossy 8 "$out" ;;
        motion-cornell-glossy-16) motion cornell-glossy 16 "$out" ;;
        *) echo "unknown item $item; items: ${ALL[*]}" >&2; exit 2 ;;
    esac
    mkdir -p "$DEST/$item"
    cp "$out/results.csv" "$out/rel_mse_vs_time.png" "$out/equal_time.png" "$DEST/$item/"
    echo "$item: $DEST/$item"
done
