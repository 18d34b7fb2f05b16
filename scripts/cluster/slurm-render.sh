#!/usr/bin/env bash
# Renders SCENE on a Slurm cluster in N independent parts and merges them
# into OUT: a job array (one task per part) and a merge job that starts
# once every task has succeeded. Prints the two job ids:
#
#   render JOBID
#   merge JOBID
#
# Usage: slurm-render.sh SCENE OUT --parts N [--split tiles|samples] [pinhole render options]
#
# --split tiles (the default) cuts the frame into N bands of rows, merged
# bit for bit; --split samples gives each part a range of the --spp samples
# of every pixel. The parts and their logs go to OUT.parts/ (or PARTS_DIR).
# PINHOLE names the binary (default: `pinhole` on PATH); sbatch options such
# as --partition or --cpus-per-task go in SBATCH_* variables or SBATCH_ARGS.
set -euo pipefail
usage() { echo "usage: slurm-render.sh SCENE OUT --parts N [--split tiles|samples] [pinhole render options]" >&2; exit 2; }
[ $# -ge 2 ] || usage
scene=$1 out=$2
shift 2
parts="" split=tiles spp=1 opts=()
while [ $# -gt 0 ]; do
    case $1 in
        --parts) [ $# -ge 2 ] || usage; parts=$2; shift 2 ;;
        --split) [ $# -ge 2 ] || usage; split=$2; shift 2 ;;
        --spp) [ $# -ge 2 ] || usage; spp=$2; opts+=("$1" "$2"); shift 2 ;;
        *) opts+=("$1"); shift ;;
    esac
done
case $parts in ''|*[!0-9]*|0) echo "slurm-render.sh: --parts needs a whole number of at least 1" >&2; exit 2 ;; esac
case $split in
    tiles) ;;
    samples) [ "$parts" -le "$spp" ] || { echo "slurm-render.sh: --parts $parts is more than --spp $spp samples to split" >&2; exit 2; } ;;
    *) echo "slurm-render.sh: --split \"$split\" is neither tiles nor samples" >&2; exit 2 ;;
esac
here=$(cd "$(dirname "$0")" && pwd)
pinhole=${PINHOLE:-$(command -v pinhole || true)}
[ -n "$pinhole" ] || { echo "slurm-render.sh: no pinhole binary (set PINHOLE or put pinhole on PATH)" >&2; exit 2; }
pinhole=$(readlink -f "$pinhole")
out=$(readlink -f "$(dirname "$out")")/$(basename "$out")
partdir=${PARTS_DIR:-$out.parts}
mkdir -p "$partdir"
partdir=$(readlink -f "$partdir")
# shellcheck disable=SC2086  # SBATCH_ARGS is a list of options
render=$(sbatch --parsable ${SBATCH_ARGS:-} --array="0-$((parts - 1))" -o "$partdir/part-%a.log" \
    "$here/render-part.sh" "$pinhole" "$scene" "$partdir" "$parts" "$split" "$spp" "${opts[@]}")
render=${render%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --dependency="afterok:$render" --kill-on-invalid-dep=yes -o "$partdir/merge.log" \
    "$here/merge-parts.sh" "$pinhole" "$out" "$partdir" "$parts")
merge=${merge%%;*}
echo "render $render"
echo "merge $merge"
