#!/usr/bin/env bash
# Instructions a frame executes, counted by valgrind's callgrind: the same
# count on every run, where a shared machine's frame times swing by tens of
# percent from one minute to the next. For telling whether a change to the
# hot loops does less work before timing it (the count is not the time:
# a cache miss costs no instruction, and valgrind runs the AVX2 code path,
# having no AVX-512). One thread, small images; each case is
# `pinhole bench ... --frames 1` (a first frame and one warm frame), the
# count taken inside the frame only (not loading or the BVH build).
#
#   bash scripts/count_instructions.sh              (the three cases below)
#   BASE_BIN=older/pinhole bash scripts/count_instructions.sh
#
# Needs valgrind (apt-get install -y valgrind). About a minute a binary.
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
bin=target/release/pinhole
cargo build --release --quiet
bins=("$bin")
[ -n "${BASE_BIN:-}" ] && bins=("$BASE_BIN" "$bin")
cases=(
    "path|$shared/references/bunny_ground.toml --gi path --spp 16 --width 160 --height 90"
    "raycast|$shared/bench/stanford-bunny.toml --width 640 --height 360"
    "raster|$shared/bench/teapot.toml --renderer rasterize --shadows none --width 640 --height 360"
)
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for c in "${cases[@]}"; do
    label=${c%%|*}
    read -r -a args <<< "${c#*|}"
    counts=()
    for b in "${bins[@]}"; do
        # The frame's instructions only: collection is on inside the frame.
        n=$(valgrind --tool=callgrind --toggle-collect='*render_frame_with' --callgrind-out-file="$out" \
            "$b" bench "${args[@]}" --frames 1 --threads 1 2>&1 >/dev/null | sed -nE 's/.*refs: *([0-9,]+).*/\1/p' | tr -d ,)
        # The collection starts at `render_frame_with`'s own symbol: were
        # the compiler to inline it, nothing would be counted.
        if [ -z "$n" ] || [ "$n" = 0 ]; then
            echo "count_instructions.sh: no instructions counted for $b on $label: is render_frame_with still a function of its own in that binary?" >&2
            exit 1
        fi
        counts+=("$n")
        printf '%-8s %-40s %6.1f M instructions (two frames)\n' "$label" "$b" "$(python3 -c "print($n / 1e6)")"
    done
    if [ ${#counts[@]} -eq 2 ]; then
        python3 -c "print(f'$label: {(${counts[1]} / ${counts[0]} - 1) * 100:+.2f}% against BASE_BIN')"
    fi
done
