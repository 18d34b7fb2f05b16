#!/usr/bin/env bash
# Merges the N parts PARTDIR/part-0.exr .. part-(N-1).exr into OUT (and the
# whole render's statistics into OUT.json). Naming every part, instead of a
# glob, lets the merge name a missing one.
#
#   merge-parts.sh PINHOLE OUT PARTDIR N
#SBATCH --job-name=pinhole-merge
set -euo pipefail
pinhole=$1 out=$2 partdir=$3 n=$4
parts=()
for ((i = 0; i < n; i++)); do parts+=("$partdir/part-$i.exr"); done
exec "$pinhole" merge "${parts[@]}" -o "$out" --stats "$out.json"
