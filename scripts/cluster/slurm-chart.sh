#!/usr/bin/env bash
# Runs a plan written by `pinhole chart --plan DIR` (or `pinhole gallery
# --plan DIR`) on a Slurm cluster: a job array with one task per line of
# DIR/jobs.txt, and a job that runs DIR/assemble.txt once every task has
# succeeded. Prints the two job ids:
#
#   jobs JOBID
#   assemble JOBID
#
# Usage: slurm-chart.sh DIR
#
# The logs go to DIR/job-I.log and DIR/assemble.log. sbatch options such as
# --partition or --cpus-per-task go in SBATCH_* variables or SBATCH_ARGS.
# The lines name the pinhole binary that wrote the plan by its full path:
# the nodes must see it there (or edit jobs.txt and assemble.txt).
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: slurm-chart.sh PLAN_DIR" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
dir=$(readlink -f "$1")
[ -f "$dir/jobs.txt" ] && [ -f "$dir/assemble.txt" ] || { echo "slurm-chart.sh: $dir holds no plan (jobs.txt and assemble.txt)" >&2; exit 2; }
n=$(grep -c . "$dir/jobs.txt" || true)
[ "$n" -ge 1 ] || { echo "slurm-chart.sh: $dir/jobs.txt has no jobs" >&2; exit 2; }
# shellcheck disable=SC2086  # SBATCH_ARGS is a list of options
jobs=$(sbatch --parsable ${SBATCH_ARGS:-} --array="0-$((n - 1))" -o "$dir/job-%a.log" "$here/run-plan-line.sh" "$dir")
jobs=${jobs%%;*}
# shellcheck disable=SC2086
assemble=$(sbatch --parsable ${SBATCH_ARGS:-} --job-name=pinhole-assemble --dependency="afterok:$jobs" --kill-on-invalid-dep=yes \
    -o "$dir/assemble.log" --wrap "bash $(printf %q "$dir/assemble.txt")")
assemble=${assemble%%;*}
echo "jobs $jobs"
echo "assemble $assemble"
