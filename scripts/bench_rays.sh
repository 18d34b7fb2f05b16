#!/usr/bin/env bash
# Incoherent rays, one thread: the first bounce of a path tracer (one
# cosine-sampled direction from each primary hit), traced one at a time by
# pinhole's BVH and by Embree 3 over the same triangles and rays. Scenes
# without spheres only (Embree is given the triangles). Pinhole's figures:
# `bounce_ns_per_ray` with each hit's full record built one at a time
# (`closest`), `bounce_walk_ns_per_ray` the walk alone as path frames call
# it (`closest_for_batch`: the hit's triangle and weights); Embree's:
# single rays (`rtcIntersect1`) and packets of 16 consecutive rays
# (`rtcIntersect16`, as Mitsuba 3's LLVM variants call it on AVX-512).
#
#   bash scripts/bench_rays.sh [SCENE.toml ...]     (default: bunny_ground)
#
# Needs libembree-dev and g++ (see scripts/bench_peers.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
shared=$(cd ../shared && pwd)
scenes=("$@")
[ ${#scenes[@]} -eq 0 ] && scenes=("$shared/references/bunny_ground.toml")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cargo build --release --quiet --example bvh_speed
g++ -O3 -march=native -std=c++17 scripts/peers/embree_rays.cpp -o "$out/embree_rays" -lembree3
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    PINHOLE_DUMP_RAYS="$out" target/release/examples/bvh_speed "$scene" | tr ' ' '\n' | grep -E '^bounce_' | sed "s/^/$name pinhole /"
    "$out/embree_rays" "$out/$name.tris" "$out/$name.rays" | sed "s/^/$name /"
done
