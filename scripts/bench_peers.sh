#!/usr/bin/env bash
# Measures pinhole against its peers (Embree 3, Mitsuba 3, llvmpipe) in ONE run, on the
# benchmark scenes, and prints the figures and ratios. Only same-run ratios
# mean anything on these shared machines.
#
#   bash scripts/bench_peers.sh [SCENE.toml ...]     (default: ../shared/bench/*.toml)
#
# Needs the peers installed: a Python venv at /tmp/peers (or PEERS_PYTHON) with
# Mitsuba 3 and the peer scripts' modules, libembree-dev, and Mesa for llvmpipe:
#   apt-get install -y libembree-dev libtbb-dev g++ libegl-mesa0 libgl1-mesa-dri
#   python3 -m venv /tmp/peers && /tmp/peers/bin/pip install mitsuba trimesh numpy moderngl
# BASE_BIN=path/to/older/pinhole adds that binary's figures to the same run
# (before and after a change).
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
py=${PEERS_PYTHON:-/tmp/peers/bin/python}
bin=target/release/pinhole
cargo build --release --quiet
bins=("$bin")
[ -n "${BASE_BIN:-}" ] && bins=("$BASE_BIN" "$bin")
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$shared"/bench/*.toml)
field() { python3 -c "import json,sys; print(json.load(sys.stdin)['$1'])"; }
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    echo "== $name"
    ( cd "$shared/bench" && "$py" ../tools/peers/embree_primary.py "$(basename "$scene")" 2 ) 2>&1 | sed 's/^/embree:   /'
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer raytrace --view depth --shadows none --frames 10 > /tmp/pinhole-primary.json
        echo "$tag:  primary rays $(field primary_rays_per_s < /tmp/pinhole-primary.json | awk '{printf "%.2f Mrays/s", $1/1e6}'), build $(field build_ms < /tmp/pinhole-primary.json | awk '{printf "%.1f ms", $1}') (depth view: eye rays + hit record, no shading)"
    done
    ( cd "$shared/bench" && "$py" ../tools/peers/mitsuba_direct.py "$(basename "$scene")" ) 2>&1 | sed 's/^/mitsuba:  /'
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer raytrace --frames 10 > /tmp/pinhole-frame.json
        echo "$tag:  ray-cast frame (primary + shadow + Blinn-Phong) $(field render_ms < /tmp/pinhole-frame.json | awk '{printf "%.1f ms", $1}')"
    done
    ( cd "$shared/bench" && "$py" ../tools/peers/llvmpipe_raster.py "$(basename "$scene")" ) 2>&1 | sed 's/^/llvmpipe: /'
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer rasterize --shadows none --frames 10 > /tmp/pinhole-raster.json
        echo "$tag:  rasterized frame (depth test + per-pixel Blinn-Phong, no shadows) $(field render_ms < /tmp/pinhole-raster.json | awk '{printf "%.1f ms", $1}')"
    done
done
