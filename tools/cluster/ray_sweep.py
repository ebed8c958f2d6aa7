#!/usr/bin/env python3
"""Runs a restir-pt job list on a Ray cluster (or a local Ray instance), then its merge.

    restir-pt compare SCENE --reference REF --budgets-ms 20,40 --out-dir out/c --plan out/c/jobs.jsonl
    python3 tools/cluster/ray_sweep.py out/c/jobs.jsonl                  # local Ray, one worker per core
    python3 tools/cluster/ray_sweep.py out/c/jobs.jsonl --address auto   # an existing cluster (ray start)

Each job of the plan (one JSON line: argv, cwd) becomes a Ray task that runs
`restir-pt <argv>` from `cwd`; when every task has succeeded, the merge command of the plan runs
here. Jobs write their files under the plan's output folder, which all nodes must share. A job
that fails is reported with the end of its stderr and the merge does not run (exit code 1).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

import ray


def restir_pt_binary(cwd, given):
    """$RESTIR_PT or --restir-pt, else restir-pt on PATH, else target/release under cwd."""
    if given:
        return given
    return shutil.which("restir-pt") or os.path.join(cwd, "target", "release", "restir-pt")


@ray.remote
def run_job(line, binary):
    """Runs one job; returns (job, exit code, the end of stderr)."""
    exe = restir_pt_binary(line["cwd"], binary)
    done = subprocess.run([exe] + line["argv"], cwd=line["cwd"], capture_output=True, text=True)
    return line["job"], done.returncode, done.stderr[-2000:]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("plan", help="the job list written by --plan")
    parser.add_argument("--address", help="a running Ray cluster (e.g. auto); default: start a local one")
    parser.add_argument("--num-cpus", type=int, help="local Ray: worker slots (default: the cores)")
    parser.add_argument("--cpus-per-job", type=float, default=1.0, help="CPU slots each job takes")
    parser.add_argument("--gpus-per-job", type=float, default=0.0, help="GPU slots each job takes")
    parser.add_argument("--restir-pt", default=os.environ.get("RESTIR_PT"), help="the restir-pt binary")
    args = parser.parse_args()

    with open(args.plan) as f:
        lines = [json.loads(l) for l in f if l.strip()]
    if not lines:
        sys.exit(f"{args.plan}: no jobs")

    if args.address:
        ray.init(address=args.address)
    else:
        ray.init(num_cpus=args.num_cpus, include_dashboard=False)
    task = run_job.options(num_cpus=args.cpus_per_job, num_gpus=args.gpus_per_job)
    pending = [task.remote(line, args.restir_pt) for line in lines]
    failed = []
    while pending:
        ready, pending = ray.wait(pending, num_returns=1)
        job, code, stderr = ray.get(ready[0])
        label = lines[job]["label"]
        print(f"job {job} of {len(lines)} ({label}): exit {code}", flush=True)
        if code != 0:
            failed.append(job)
            sys.stderr.write(stderr)
    ray.shutdown()
    if failed:
        sys.exit(f"{args.plan}: jobs {sorted(failed)} failed; not merging")

    line = lines[0]
    merge = subprocess.run([restir_pt_binary(line["cwd"], args.restir_pt)] + line["merge_argv"], cwd=line["cwd"])
    sys.exit(merge.returncode)


if __name__ == "__main__":
    main()
