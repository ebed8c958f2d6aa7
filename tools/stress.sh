#!/usr/bin/env bash
# Stress run for driver crashes under load: for MINUTES (default 30), again and again, the suite's
# stress tests (many devices on threads, each rendering and dropping, then a validated one) beside
# the ReSTIR tests (the load under which the crash first appeared). Counts runs that died of a
# signal or failed, and keeps their logs in OUT (default out/stress). Exit status 1 if any.
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
: >"$out/tally"
# Runs the suite with "$@" again and again until the deadline, each run's log in
# $out/$name-N.log. A run stopped at the deadline (`timeout`'s 124) is no failure; a signal of
# the process's own is a crash.
repeat() {
  local name=$1 n=0 left rc
  shift
  while [ "$(date +%s)" -lt "$end" ]; do
    n=$((n + 1))
    left=$(( end - $(date +%s) ))
    timeout "$left" env RESTIR_PT_STRESS_SECONDS=120 "$suite" "$@" >"$out/$name-$n.log" 2>&1
    rc=$?
    if [ "$rc" -eq 124 ]; then echo "$name run $n: stopped at the deadline"
    elif [ "$rc" -gt 128 ]; then echo crash >>"$out/tally"; echo "$name run $n: died of signal $((rc - 128))"
    elif [ "$rc" -ne 0 ]; then echo fail >>"$out/tally"; echo "$name run $n: failed (exit $rc)"
    else echo "$name run $n: passed (load $(cut -d' ' -f1-3 /proc/loadavg))"; fi
  done
}
# The stress tests again and again beside the ReSTIR tests, each in one process on one test
# thread: validated devices must not be made or dropped on one thread while another uses one, a
# race in Debian's validation layer (docs/testing.md).
repeat stress --test-threads=1 stress_ &
repeat restir --test-threads=1 restir &
wait
runs=$(ls "$out" | grep -c '\.log$')
crashed=$(grep -c crash "$out/tally")
failed=$(grep -c fail "$out/tally")
echo "tools/stress.sh: $runs runs in $minutes min: $crashed crashed, $failed failed (logs in $out)"
[ "$crashed" -eq 0 ] && [ "$failed" -eq 0 ]
