#!/usr/bin/env bash
# ReSTIR PT in motion against the path tracer at equal GPU time per frame (issue 17's bar):
# runs tools/make_results.sh's moving-camera items (veach-door and cornell-glossy, 128×128, the
# camera on the scene's path, the last of 8 and of 16 frames against a reference of its own
# pose; methods pt, restir (defaults) and restir@s0 (spatial reuse off); 8 trials per point),
# then writes docs/results/motion-summary.md: every ReSTIR PT row against the path tracer at the
# same ms per frame.
#
# The path tracer's relMSE at a ReSTIR PT row's time t comes from its own rows: relMSE × time,
# constant for an estimator whose variance falls as 1/spp, is interpolated linearly in log t
# between the two path-tracer rows around t (the nearest row's value outside them), and divided
# by t. "vs @s0" is the same for spatial reuse on against off: relMSE × time of restir@s0 at t
# over the row's.
#
# Usage: tools/motion_results.sh [ITEM...]   (default: the README's four items, 8 and 16 frames
#   of each scene; about 20 minutes on a quiet 2-core machine once the references exist).
#   Environment as tools/make_results.sh (RESTIR_PT, DEST, WORK, TRIALS); SUMMARY_ONLY=1
#   rewrites the summary from the results already in DEST.
set -euo pipefail
cd "$(dirname "$0")/.."

DEST=${DEST:-docs/results}
items=("$@")
[[ ${#items[@]} -gt 0 ]] || items=(motion-veach-door-8 motion-cornell-glossy-8 motion-veach-door-16 motion-cornell-glossy-16)
[[ -n ${SUMMARY_ONLY:-} ]] || DEST=$DEST tools/make_results.sh "${items[@]}"

python3 - "$DEST" "${items[@]}" <<'EOF'
import csv, math, sys

dest, items = sys.argv[1], sys.argv[2:]


def at_time(rows, t):
    """relMSE of `rows` (a method's (ms, relMSE, relative standard error) points) at t ms per
    frame, relMSE x time interpolated linearly in log time; with its relative standard error,
    interpolated the same way (None where a row has none)."""
    pts = sorted((ms, ms * e, rse) for ms, e, rse in rows)
    if t <= pts[0][0]:
        return pts[0][1] / t, pts[0][2]
    if t >= pts[-1][0]:
        return pts[-1][1] / t, pts[-1][2]
    for (t0, p0, r0), (t1, p1, r1) in zip(pts, pts[1:]):
        if t0 <= t <= t1:
            a = (math.log(t) - math.log(t0)) / (math.log(t1) - math.log(t0))
            rse = None if r0 is None or r1 is None else r0 + a * (r1 - r0)
            return (p0 + a * (p1 - p0)) / t, rse


def ratio(num, den):
    """num / den with its standard error from the two relative standard errors (first order,
    independent runs); '' for the error where either has none."""
    (a, ra), (b, rb) = num, den
    q = a / b
    if ra is None or rb is None:
        return f"**{q:.2f}x**"
    return f"**{q:.2f}x** ± {q * math.hypot(ra, rb):.2f}"


def point(r):
    e = float(r["rel_mse"])
    se = r.get("rel_mse_stderr") or ""
    return float(r["gpu_ms_per_frame"]), e, (float(se) / e if se else None)


lines = [
    "# ReSTIR PT in motion against the path tracer at equal time",
    "",
    "Made by `tools/motion_results.sh`; rows from docs/results/ITEM/results.csv. `pt at t`: the",
    "path tracer's relMSE at the row's ms per frame (relMSE x time interpolated in log time between",
    "its rows); `vs @s0`: the same for restir@s0 (spatial reuse off) against the row. ± is one",
    "standard error of the ratio, from the relMSE's standard error over the trials.",
    "",
    "| item | method | knob | ms per frame | relMSE | trimmed | pt at t | pt / ReSTIR | vs @s0 |",
    "|---|---|---|---|---|---|---|---|---|",
]
for item in items:
    with open(f"{dest}/{item}/results.csv") as f:
        rows = list(csv.DictReader(f))
    by = {}
    for r in rows:
        by.setdefault(r["method"], []).append(point(r))
    pt = by.get("pt")
    off = next((v for k, v in by.items() if k.endswith("@s0")), None)
    for r in rows:
        if r["method"] == "pt":
            continue
        t, e, rse = point(r)
        e_pt = at_time(pt, t)
        vs = "" if r["method"].endswith("@s0") or off is None else ratio(at_time(off, t), (e, rse)).replace("**", "")
        lines.append(
            f"| {item} | {r['method']} | {r['knob']} | {t:.1f} | {e:.4g} | {float(r['rel_mse_trimmed']):.4g} "
            f"| {e_pt[0]:.4g} | {ratio(e_pt, (e, rse))} | {vs} |"
        )
with open(f"{dest}/motion-summary.md", "w") as f:
    f.write("\n".join(lines) + "\n")
print("\n".join(lines))
EOF
