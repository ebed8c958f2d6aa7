#!/bin/bash
# restir-pt beside Mitsuba 3 (scalar_rgb and llvm_ad_rgb) on one job, in one run
# (docs/performance.md). Usage: [SPP=64] tools/bench_vs_mitsuba.sh [SCENE] [ROUNDS]; set BASE to another
# restir-pt binary (e.g. main's) to alternate it in. Needs `pip install mitsuba` and, for
# llvm_ad_rgb on Debian 12, libllvm19 (DRJIT_LIBLLVM_PATH below).
set -e
cd "$(dirname "$0")/.."
SCENE=${1:-scenes/cornell.gltf}
ROUNDS=${2:-1}
JOB="--width 256 --height 256 --spp ${SPP:-64} --max-depth 8"
export DRJIT_LIBLLVM_PATH=${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1}
for r in $(seq "$ROUNDS"); do
    if [ -n "$BASE" ]; then
        echo "base: $("$BASE" bench "$SCENE" $JOB --runs 5 --russian-roulette off 2>/dev/null | tr '\n' ' ')"
    fi
    echo "restir-pt: $(target/release/restir-pt bench "$SCENE" $JOB --runs 5 --russian-roulette off 2>/dev/null)"
    for variant in scalar_rgb llvm_ad_rgb; do
        python3 tools/mitsuba_bench.py "$SCENE" --variant $variant $JOB --runs 5 2>/dev/null
    done
done
