#!/usr/bin/env bash
# The loader's fuzz corpus: build the libFuzzer target, grow a corpus by fuzzing, and minimise it
# to the inputs that add edge coverage. What `cargo fuzz build/run/cmin load_scene` does, without
# needing cargo-fuzz installed: a nightly toolchain (`rustup toolchain install nightly`) and a C++
# compiler for libFuzzer are enough.
#
# Usage:
#   tools/fuzz_corpus.sh build                 instrumented fuzz/target/.../release/load_scene
#   tools/fuzz_corpus.sh grow [SECONDS]        fuzz (default 600 s) from the tracked corpus, the
#                                              bad-input corpus and the scenes into $FULL
#   tools/fuzz_corpus.sh minimise [DIR...]     replace fuzz/corpus/load_scene by the smallest set
#                                              of inputs from it and DIR... ($FULL if it exists)
#                                              that covers every edge they cover together
# $FULL defaults to fuzz/corpus-full (ignored by git). The tracked corpus is the minimised one;
# the suite replays it, and fuzz/regressions/load_scene (inputs that once crashed the loader),
# in robustness_fuzz_corpus_replays_without_panic.
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=x86_64-unknown-linux-gnu
BIN=fuzz/target/$TARGET/release/load_scene
CORPUS=fuzz/corpus/load_scene
FULL=${FULL:-fuzz/corpus-full}

build() {
    # cargo-fuzz's default flags without a sanitizer: edge coverage with inline 8-bit counters,
    # and debug assertions and overflow checks on, which is how the loader's crashes were found.
    (cd fuzz && RUSTFLAGS="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=3 \
        -Cllvm-args=-sanitizer-coverage-inline-8bit-counters -Cllvm-args=-sanitizer-coverage-pc-table \
        --cfg fuzzing -Cdebug-assertions -Coverflow-checks" \
        cargo +nightly build --release --bin load_scene --target "$TARGET")
}

case ${1:-} in
    build) build ;;
    grow)
        [[ -x $BIN ]] || build
        mkdir -p "$FULL"
        "$BIN" "$FULL" "$CORPUS" fuzz/regressions/load_scene tests/data/bad scenes \
            -max_total_time="${2:-600}" -max_len=16384 -timeout=10 -rss_limit_mb=4096
        ;;
    minimise)
        [[ -x $BIN ]] || build
        shift
        sources=("$@")
        [[ ${#sources[@]} -gt 0 || ! -d $FULL ]] || sources=("$FULL")
        new=$(mktemp -d)
        # -use_counters=0: an input is kept for an edge no other kept input reaches, not for a
        # new hit count of an edge already covered.
        "$BIN" -merge=1 -use_counters=0 -timeout=10 -rss_limit_mb=4096 "$new" "$CORPUS" "${sources[@]}"
        before=$(find "$CORPUS" -type f | wc -l)
        rm -rf "$CORPUS"
        mkdir -p "$CORPUS"
        cp "$new"/* "$CORPUS"/
        rm -rf "$new"
        echo "$CORPUS: $before -> $(find "$CORPUS" -type f | wc -l) inputs"
        ;;
    *) sed -n '2,17p' "$0" >&2; exit 2 ;;
esac
