#!/bin/bash
# restir-pt's path tracer beside Mitsuba 3 on glTF files (docs/independent-check.md): for each file,
# tools/mitsuba_reference.py's render and statistics and `restir-pt render --method pt` at the
# same size, then one markdown row: mean RGB of each, the largest and smallest per-tile ratio
# restir-pt / Mitsuba over the tile channels of at least 0.05, and the ratio of the means.
# Usage: [SIZE=64] [SPP=1024] tools/independent_check.sh FILE...   (images in out/independent/)
# Needs `pip install mitsuba pygltflib numpy pillow` and a release build.
set -e
cd "$(dirname "$0")/.."
SIZE=${SIZE:-64}
SPP=${SPP:-1024}
OUT=out/independent
mkdir -p "$OUT"
echo "| file | restir-pt mean RGB | Mitsuba mean RGB | ratio of means | tile ratios (min, max) |"
echo "|---|---|---|---|---|"
for file in "$@"; do
    name=$(basename "$file" .gltf)
    python3 tools/mitsuba_reference.py "$file" --width "$SIZE" --height "$SIZE" --spp "$SPP" --passes 8 \
        --out "$OUT/$name-mitsuba.exr" --json "$OUT/$name-mitsuba.json" >/dev/null 2>&1
    target/release/restir-pt render "$file" --method pt --spp "$SPP" --width "$SIZE" --height "$SIZE" \
        --exposure 0 --out "$OUT/$name-restir-pt.exr" >/dev/null 2>&1
    python3 - "$OUT/$name-restir-pt.exr" "$OUT/$name-mitsuba.json" "$file" <<'EOF'
import json, sys
import numpy as np
sys.path.insert(0, "tools")
from mitsuba_reference import read_exr, tile_means
exr, ref_path, file = sys.argv[1:4]
ref = json.load(open(ref_path))
img = read_exr(exr)
ours, theirs = tile_means(img, ref["settings"]["tiles"]), np.array(ref["tile_mean_rgb"])
bright = theirs >= 0.05
ratios = ours[bright] / theirs[bright]
mean = img[:, :, :3].reshape(-1, 3).mean(0)
fmt = lambda v: "(" + ", ".join("%.4f" % x for x in v) + ")"
print("| %s | %s | %s | %s | %.3f, %.3f |" % (file, fmt(mean), fmt(ref["mean_rgb"]),
      fmt(mean / np.maximum(ref["mean_rgb"], 1e-9)), ratios.min(), ratios.max()))
EOF
done
