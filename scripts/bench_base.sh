#!/usr/bin/env bash
# Before and after a change, on this machine, in one run: each round times a
# frame with the base binary, then with the working tree's, one right after
# the other (`pinhole bench --frames 3`: the best of three warm frames), and
# prints each round's ratio new/base and per case the median over the rounds.
# No peer is needed; for the peers' ratios see bench_peers.sh and bench_gi.sh.
#
#   BASE_BIN=/path/to/old/pinhole bash scripts/bench_base.sh   (ROUNDS=5, default 3)
set -euo pipefail
cd "$(dirname "$0")/.."
: "${BASE_BIN:?set BASE_BIN to the base binary}"
rounds=${ROUNDS:-3}
bin=target/release/pinhole
cargo build --release --quiet --bin pinhole
cases=(
    "bunny --renderer raytrace"
    "bunny --renderer rasterize"
    "teapot --renderer raytrace --spp 4"
    "teapot --renderer rasterize --shadows map"
    "cornell-gi --renderer raytrace --gi path --spp 16 --width 320 --height 240"
)
ms() { "$@" --frames 3 | sed -nE 's/.*"render_ms_min": *([0-9.]+).*/\1/p'; }
for c in "${cases[@]}"; do
    ratios=()
    for _ in $(seq 1 "$rounds"); do
        # shellcheck disable=SC2086
        b=$(ms "$BASE_BIN" bench $c)
        # shellcheck disable=SC2086
        n=$(ms "$bin" bench $c)
        ratios+=("$(python3 -c "print(f'{$n / $b:.3f}')")")
    done
    median=$(printf '%s\n' "${ratios[@]}" | sort -n | sed -n "$(( (rounds + 1) / 2 ))p")
    echo "$c: new/base ${ratios[*]} (median $median)"
done
