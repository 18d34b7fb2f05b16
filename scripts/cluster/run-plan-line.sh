#!/usr/bin/env bash
# Runs one line of a plan written by `pinhole chart --plan DIR` or
# `pinhole gallery --plan DIR`: line I+1 of DIR/jobs.txt, where I comes
# from the engine that runs it (Slurm's job array, a Kubernetes Indexed
# Job) or from PART_INDEX.
#
#   run-plan-line.sh DIR
#SBATCH --job-name=pinhole-plan
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: run-plan-line.sh PLAN_DIR" >&2; exit 2; }
jobs=$1/jobs.txt
i=${SLURM_ARRAY_TASK_ID:-${JOB_COMPLETION_INDEX:-${PART_INDEX:-}}}
[ -n "$i" ] || { echo "run-plan-line.sh: no job index (SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX or PART_INDEX)" >&2; exit 2; }
line=$(sed -n "$((i + 1))p" "$jobs")
[ -n "$line" ] || { echo "run-plan-line.sh: $jobs has no line $((i + 1))" >&2; exit 2; }
# The plan wrote each line as shell words (quoted where needed).
exec bash -c "$line"
