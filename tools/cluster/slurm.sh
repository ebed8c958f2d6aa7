#!/usr/bin/env bash
# Runs a restir-pt job list (`compare ... --plan jobs.jsonl`, `stability ... --plan jobs.jsonl`)
# as a Slurm job array, then its merge as a job that waits for the whole array.
#
#   tools/cluster/slurm.sh submit jobs.jsonl [sbatch options...]   # on the login node
#   tools/cluster/slurm.sh job jobs.jsonl                          # what each array task runs
#   tools/cluster/slurm.sh merge jobs.jsonl                        # what the merge job runs
#
# `submit` calls sbatch twice: an array of one task per line of the plan (task K runs the
# plan's line K), and the merge with --dependency=afterok on the array. The sbatch options
# (partition, --gres=gpu:1, --time, ...) apply to both. Every task runs from the folder the plan
# was written in (its "cwd"), so the plan's relative paths and the output folder must be on a
# file system all nodes share. The binary is $RESTIR_PT, else restir-pt on PATH, else
# target/release/restir-pt under that folder. Needs python3 (to read the JSON lines).
#SBATCH --job-name=restir-pt
#SBATCH --output=restir-pt-%A_%a.log
set -euo pipefail

usage() {
  echo "usage: $0 submit|job|merge PLAN.jsonl [sbatch options...]" >&2
  exit 2
}

[ "$#" -ge 2 ] || usage
mode=$1
plan=$2
shift 2
[ -f "$plan" ] || { echo "$0: $plan: no such plan" >&2; exit 1; }
plan=$(cd "$(dirname "$plan")" && pwd)/$(basename "$plan")
script=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/$(basename "${BASH_SOURCE[0]}")

# Prints line K of the plan's field ($2: argv or merge_argv) NUL-separated, then its cwd.
field() {
  python3 - "$plan" "$1" "$2" <<'PY'
import json, sys
plan, k, key = sys.argv[1], int(sys.argv[2]), sys.argv[3]
with open(plan) as f:
    lines = [json.loads(l) for l in f if l.strip()]
if not 0 <= k < len(lines):
    sys.exit(f"{plan}: no job {k} (the plan has {len(lines)})")
line = lines[k]
sys.stdout.write(line["cwd"] + "\0" + "\0".join(line[key]))
PY
}

# Runs the plan's line $1, field $2, from its working folder.
run_line() {
  local parts=()
  mapfile -d '' parts < <(field "$1" "$2")
  [ "${#parts[@]}" -ge 2 ] || { echo "$0: $plan: line $1 has no $2" >&2; exit 1; }
  cd "${parts[0]}"
  local bin=${RESTIR_PT:-}
  if [ -z "$bin" ]; then
    bin=$(command -v restir-pt || echo "${parts[0]}/target/release/restir-pt")
  fi
  exec "$bin" "${parts[@]:1}"
}

case "$mode" in
  submit)
    jobs=$(grep -c . "$plan")
    [ "$jobs" -ge 1 ] || { echo "$0: $plan has no jobs" >&2; exit 1; }
    array=$(sbatch --parsable --array="0-$((jobs - 1))" "$@" "$script" job "$plan")
    array=${array%%;*}
    merge=$(sbatch --parsable --dependency="afterok:$array" "$@" "$script" merge "$plan")
    echo "submitted $jobs jobs as array $array and the merge as ${merge%%;*}"
    ;;
  job)
    [ -n "${SLURM_ARRAY_TASK_ID:-}" ] || { echo "$0: job needs SLURM_ARRAY_TASK_ID (run it through submit)" >&2; exit 1; }
    run_line "$SLURM_ARRAY_TASK_ID" argv
    ;;
  merge)
    run_line 0 merge_argv
    ;;
  *)
    usage
    ;;
esac
