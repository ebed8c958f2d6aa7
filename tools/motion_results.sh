#!/usr/bin/env bash
# ReSTIR PT in motion against the path tracer at equal GPU time per frame (issue 17's bar):
# runs tools/make_results.sh's moving-camera items (veach-door and cornell-glossy, 128×128, the
# camera on the scene's path, the last of 8 and of 16 frames against a reference of its own
# pose; methods pt, restir (defaults) and restir@s0 (spatial reuse off); 4 trials per point),
# then writes docs/results/motion-summary.md: every ReSTIR PT row against the path tracer at the
# same ms per frame.
#
# The path tracer's relMSE at a ReSTIR PT row's time t comes from its own rows: relMSE × time,
# constant for an estimator whose variance falls as 1/spp, is interpolated linearly in log t
# between the two path-tracer rows around t (the nearest row's value outside them), and divided
# by t. "vs @s0" is the same for spatial reuse on against off: relMSE × time of restir@s0 at t
# over the row's.
#
# Usage: tools/motion_results.sh [ITEM...]   (default: the README's two 8-frame items; about half an hour on a
#   quiet 2-core machine). Environment as tools/make_results.sh (RESTIR_PT, DEST, WORK, TRIALS);
#   SUMMARY_ONLY=1 rewrites the summary from the results already in DEST.
set -euo pipefail
cd "$(dirname "$0")/.."

DEST=${DEST:-docs/results}
items=("$@")
[[ ${#items[@]} -gt 0 ]] || items=(motion-veach-door-8 motion-cornell-glossy-8)
[[ -n ${SUMMARY_ONLY:-} ]] || DEST=$DEST tools/make_results.sh "${items[@]}"

python3 - "$DEST" "${items[@]}" <<'EOF'
import csv, math, sys

dest, items = sys.argv[1], sys.argv[2:]


def at_time(rows, t):
    """relMSE of `rows` (a method's (ms, relMSE) points) at t ms per frame, relMSE x time
    interpolated linearly in log time."""
    pts = sorted((ms, ms * e) for ms, e in rows)
    if t <= pts[0][0]:
        return pts[0][1] / t
    if t >= pts[-1][0]:
        return pts[-1][1] / t
    for (t0, p0), (t1, p1) in zip(pts, pts[1:]):
        if t0 <= t <= t1:
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            return (p0 + a * (p1 - p0)) / t


lines = [
    "# ReSTIR PT in motion against the path tracer at equal time",
    "",
    "Made by `tools/motion_results.sh`; rows from docs/results/ITEM/results.csv. `pt at t`: the",
    "path tracer's relMSE at the row's ms per frame (relMSE x time interpolated in log time between",
    "its rows); `vs @s0`: the same for restir@s0 (spatial reuse off) against the row.",
    "",
    "| item | method | knob | ms per frame | relMSE | trimmed | pt at t | pt / ReSTIR | vs @s0 |",
    "|---|---|---|---|---|---|---|---|---|",
]
for item in items:
    with open(f"{dest}/{item}/results.csv") as f:
        rows = list(csv.DictReader(f))
    by = {}
    for r in rows:
        by.setdefault(r["method"], []).append((float(r["gpu_ms_per_frame"]), float(r["rel_mse"])))
    pt = by.get("pt")
    off = next((v for k, v in by.items() if k.endswith("@s0")), None)
    for r in rows:
        if r["method"] == "pt":
            continue
        t, e = float(r["gpu_ms_per_frame"]), float(r["rel_mse"])
        e_pt = at_time(pt, t)
        vs = "" if r["method"].endswith("@s0") or off is None else f"{at_time(off, t) / e:.2f}x"
        lines.append(
            f"| {item} | {r['method']} | {r['knob']} | {t:.1f} | {e:.4g} | {float(r['rel_mse_trimmed']):.4g} "
            f"| {e_pt:.4g} | **{e_pt / e:.2f}x** | {vs} |"
        )
with open(f"{dest}/motion-summary.md", "w") as f:
    f.write("\n".join(lines) + "\n")
print("\n".join(lines))
EOF
