#!/usr/bin/env bash
# One part of a split render: the part's index comes from the engine that
# runs it (Slurm's job array, a Kubernetes Indexed Job), or from PART_INDEX.
#
#   render-part.sh PINHOLE SCENE PARTDIR N tiles|samples SPP [pinhole options]
#
# Part I of N is `--tile I/N`, or `--sample-range` I*SPP/N..(I+1)*SPP/N,
# written to PARTDIR/part-I.exr.
#SBATCH --job-name=pinhole-part
set -euo pipefail
pinhole=$1 scene=$2 partdir=$3 n=$4 split=$5 spp=$6
shift 6
i=${SLURM_ARRAY_TASK_ID:-${JOB_COMPLETION_INDEX:-${PART_INDEX:-}}}
if [ -z "$i" ]; then
    echo "render-part.sh: no part index (SLURM_ARRAY_TASK_ID, JOB_COMPLETION_INDEX or PART_INDEX)" >&2
    exit 2
fi
case $split in
    tiles) part=(--tile "$i/$n") ;;
    samples) part=(--sample-range "$((i * spp / n))..$(((i + 1) * spp / n))") ;;
    *) echo "render-part.sh: split \"$split\" is neither tiles nor samples" >&2; exit 2 ;;
esac
exec "$pinhole" render "$scene" -o "$partdir/part-$i.exr" "${part[@]}" "$@"
