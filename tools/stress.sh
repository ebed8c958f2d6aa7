#!/usr/bin/env bash
# Stress run for driver crashes under load: for MINUTES (default 30), again and again, the suite's
# stress tests (many validated devices on threads, each rendering and dropping) beside the ReSTIR
# tests run as threads of one process (the way the crash first appeared). Counts runs that died
# of a signal or failed, and keeps their logs in OUT (default out/stress). Exit status 1 if any.
# Usage: tools/stress.sh [MINUTES] [OUT]
set -uo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-30}
out=${2:-out/stress}
mkdir -p "$out"
cargo test --release --no-run >/dev/null 2>&1 || { echo "tools/stress.sh: the suite does not build" >&2; exit 1; }
suite=$(cargo test --release --no-run --message-format=json 2>/dev/null |
  python3 -c 'import json,sys
for l in sys.stdin:
    m = json.loads(l)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "suite" and m.get("executable"):
        print(m["executable"])')
[ -x "$suite" ] || { echo "tools/stress.sh: no suite binary found" >&2; exit 1; }
end=$(( $(date +%s) + 60 * minutes ))
runs=0; crashed=0; failed=0
while [ "$(date +%s)" -lt "$end" ]; do
  runs=$((runs + 1))
  # The ReSTIR tests take longer than a short run: both processes stop at the deadline, which
  # `timeout` reports as 124 and is no failure; a signal of their own is a crash.
  left=$(( end - $(date +%s) ))
  RESTIR_PT_STRESS_SECONDS=120 timeout "$left" "$suite" --test-threads=3 stress_ >"$out/stress-$runs.log" 2>&1 &
  stress=$!
  timeout "$left" "$suite" --test-threads=2 restir >"$out/restir-$runs.log" 2>&1 &
  restir=$!
  for pid in $stress $restir; do
    wait "$pid"; rc=$?
    if [ "$rc" -eq 124 ]; then echo "run $runs: process $pid stopped at the deadline";
    elif [ "$rc" -gt 128 ]; then crashed=$((crashed + 1)); echo "run $runs: process $pid died of signal $((rc - 128))";
    elif [ "$rc" -ne 0 ]; then failed=$((failed + 1)); echo "run $runs: process $pid failed (exit $rc)"; fi
  done
  echo "run $runs done ($(uptime | sed 's/.*load average: //'))"
done
echo "tools/stress.sh: $runs runs in $minutes min: $crashed crashed, $failed failed (logs in $out)"
[ "$crashed" -eq 0 ] && [ "$failed" -eq 0 ]
