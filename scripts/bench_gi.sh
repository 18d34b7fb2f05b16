#!/usr/bin/env bash
# `--gi path` at 16 spp against Mitsuba 3's `path` integrator at 16 spp, in ONE
# run, on cornell_gi and bunny_ground: each side's best of three warm renders
# after a first one (Mitsuba's `--time 3`; `pinhole bench --frames 3`).
#
#   bash scripts/bench_gi.sh            (BASE_BIN=older/pinhole adds its figures)
#
# Needs Mitsuba 3 in a Python venv at /tmp/peers (or PEERS_PYTHON); see
# scripts/bench_peers.sh for the install lines.
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
py=${PEERS_PYTHON:-/tmp/peers/bin/python}
bin=target/release/pinhole
cargo build --release --quiet
bins=("$bin")
[ -n "${BASE_BIN:-}" ] && bins=("$BASE_BIN" "$bin")
for name in cornell_gi bunny_ground; do
    scene="$shared/references/$name.toml"
    mitsuba=$("$py" "$shared/tools/reference.py" "$scene" /tmp/bench_gi_mitsuba.exr --integrator path --max-depth -1 --spp 16 --time 3 2>&1 | sed -nE 's/.*render_ms=([0-9.]+).*/\1/p')
    for b in "${bins[@]}"; do
        best=$("$b" bench "$scene" --gi path --spp 16 --frames 3 2>/dev/null | python3 -c "import json,sys; print(json.load(sys.stdin)['render_ms_min'])")
        python3 -c "print(f'$name: $b {float($best):.0f} ms, mitsuba 3 path {float($mitsuba):.0f} ms = {float($best)/float($mitsuba):.2f}x')"
    done
done
