#!/usr/bin/env bash
# Measures pinhole against its peers (Embree 3, Mitsuba 3, llvmpipe) in ONE run, on the
# benchmark scenes, and prints the figures and ratios. Only same-run ratios
# mean anything on these shared machines. Each ratio sets the same statistic
# against the same statistic: Mitsuba's script reports the best of three warm
# renders after a first one, so our ray-cast frame is the best of three warm
# frames after a first one (`bench --frames 3`, render_ms_min); llvmpipe's
# script reports the median and the fastest of 30 frames after warm-up, so our
# rasterized frame is the median and fastest of 30 (`bench --frames 30`).
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
# ratio OURS PEER: "= 0.53x" (ours over the peer's, same statistic)
ratio() { python3 -c "print('= %.2fx' % ($1 / $2))"; }
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    echo "== $name"
    ( cd "$shared/bench" && "$py" ../tools/peers/embree_primary.py "$(basename "$scene")" 2 ) 2>&1 | sed 's/^/embree:   /'
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer raytrace --view depth --shadows none --frames 10 > /tmp/pinhole-primary.json
        echo "$tag:  primary rays $(field primary_rays_per_s < /tmp/pinhole-primary.json | awk '{printf "%.2f Mrays/s", $1/1e6}'), build $(field build_ms < /tmp/pinhole-primary.json | awk '{printf "%.1f ms", $1}') (depth view: eye rays + hit record, no shading)"
    done
    mitsuba_line=$( cd "$shared/bench" && "$py" ../tools/peers/mitsuba_direct.py "$(basename "$scene")" 2>&1 )
    echo "$mitsuba_line" | sed 's/^/mitsuba:  /'
    mitsuba_best=$(echo "$mitsuba_line" | sed -nE 's/.*render_ms=([0-9.]+).*/\1/p' | tail -1)
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer raytrace --frames 3 > /tmp/pinhole-frame.json
        best=$(field render_ms_min < /tmp/pinhole-frame.json)
        echo "$tag:  ray-cast frame (primary + shadow + Blinn-Phong), best of 3 warm: $(printf %.1f "$best") ms against Mitsuba's best of 3 warm $mitsuba_best ms $(ratio "$best" "$mitsuba_best")"
    done
    llvmpipe_line=$( cd "$shared/bench" && "$py" ../tools/peers/llvmpipe_raster.py "$(basename "$scene")" 2>&1 )
    echo "$llvmpipe_line" | sed 's/^/llvmpipe: /'
    llvm_median=$(echo "$llvmpipe_line" | sed -nE 's/.* render_ms=([0-9.]+).*/\1/p' | tail -1)
    llvm_min=$(echo "$llvmpipe_line" | sed -nE 's/.*render_ms_min=([0-9.]+).*/\1/p' | tail -1)
    for b in "${bins[@]}"; do
        tag=pinhole; [ "$b" = "$bin" ] || tag="base"
        "$b" bench "$scene" --renderer rasterize --shadows none --frames 30 > /tmp/pinhole-raster.json
        median=$(field render_ms < /tmp/pinhole-raster.json)
        fastest=$(field render_ms_min < /tmp/pinhole-raster.json)
        echo "$tag:  rasterized frame (depth test + per-pixel Blinn-Phong, no shadows) of 30: median $(printf %.1f "$median") ms $(ratio "$median" "$llvm_median") llvmpipe's median, fastest $(printf %.1f "$fastest") ms $(ratio "$fastest" "$llvm_min") llvmpipe's fastest"
    done
done
