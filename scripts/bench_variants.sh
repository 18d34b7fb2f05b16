#!/usr/bin/env bash
# The rasterizer family on the benchmark scenes, with Mesa's llvmpipe measured
# in the same run: ms per frame (median of warm frames) and sample test
# efficiency (samples covered / samples tested). Same shading as llvmpipe's
# peer script: depth test, per-pixel Blinn-Phong, one point light, no shadows.
#
#   bash scripts/bench_variants.sh [SCENE.toml ...]    (default: ../shared/bench/*.toml)
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
py=${PEERS_PYTHON:-/tmp/peers/bin/python}
bin=target/release/pinhole
cargo build --release --quiet
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$shared"/bench/*.toml)
echo "| scene | renderer | ms/frame | test efficiency | fragments shaded |"
echo "|---|---|---|---|---|"
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    ms=$(cd "$shared/bench" && "$py" ../tools/peers/llvmpipe_raster.py "$(basename "$scene")" 2>/dev/null | sed -n 's/.* render_ms=\([0-9.]*\).*/\1/p')
    echo "| $name | llvmpipe | $ms | | |"
    for r in $("$bin" list | awk '/^  rasterize:/ {print $1}'); do
        frames=5
        if [ "$r" = rasterize:naive ]; then
            # Every triangle x every pixel: ~17 s a frame on the teapot, hours on the bunny.
            [ "$name" = teapot ] || { echo "| $name | $r | (not run: every triangle x every pixel) | | |"; continue; }
            frames=1
        fi
        "$bin" bench "$scene" --renderer "$r" --shadows none --frames $frames | python3 -c "
import json, sys
j = json.load(sys.stdin)
eff = j['samples_covered'] / max(j['samples_tested'], 1)
print(f\"| $name | {j['renderer']} | {j['render_ms']:.1f} | {100*eff:.1f}% | {j['fragments_shaded']} |\")"
    done
    "$bin" bench "$scene" --renderer raytrace --shadows none --frames 5 | python3 -c "
import json, sys
j = json.load(sys.stdin)
print(f\"| $name | {j['renderer']} (for comparison) | {j['render_ms']:.1f} | | |\")"
done
