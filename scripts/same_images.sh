#!/usr/bin/env bash
# Checks that a change leaves every image bit for bit as it was: renders every
# built-in scene under every renderer and every view (plus the shading knobs:
# spp, shadow maps, interpolation, MSAA, forward shading, affine) with the
# binary of BASE and with the working tree's, as linear EXR, and compares the
# files byte for byte. Also compares `pinhole pixel --json` replays.
#
#   bash scripts/same_images.sh [BASE]        (default BASE: HEAD)
#
# Images are small (96x64) so the whole matrix takes a few minutes; the bunny
# under raytrace:brute and rasterize:naive is the slow part.
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-HEAD}
work=${SAME_IMAGES_DIR:-/tmp/pinhole-same-images}
target=$(pwd)/target
rm -rf "$work"
mkdir -p "$work"

# The base is built in a worktree of its own, sharing the target directory
# (dependencies compile once); its binary is copied out before the working
# tree's build overwrites it. BASE_BIN names an already built base binary
# instead, and BASE_RENDERS a directory that keeps the base's renders between
# runs (both for repeated checks against one base).
if [ -n "${BASE_BIN:-}" ]; then
    cp "$BASE_BIN" "$work/pinhole-base"
else
    git worktree remove --force "$work/base-src" 2>/dev/null || true
    git worktree add --detach "$work/base-src" "$base" >/dev/null
    (cd "$work/base-src" && CARGO_TARGET_DIR="$target" cargo build --release --quiet --bin pinhole)
    cp "$target/release/pinhole" "$work/pinhole-base"
    git worktree remove --force "$work/base-src"
fi
cargo build --release --quiet --bin pinhole
cp "$target/release/pinhole" "$work/pinhole-new"

# The names listed under one heading of `pinhole list` (aliases and notes skipped).
section() {
    "$1" list | awk -v h="$2" '/^[^ ]/ {s = ($0 == h); next}
        s && NF && $1 !~ /^[(-]/ && $2 != "=" {print $1}'
}

# One line per render: SCENE RENDERER [options...]
cases() {
    local bin=$1
    local scenes renderers views
    scenes=$(section "$bin" "built-in scenes:")
    renderers=$(section "$bin" "renderers:")
    views=$(section "$bin" "views:")
    for s in $scenes; do
        for r in $renderers; do
            for v in $views; do
                echo "$s $r --view $v"
            done
            echo "$s $r --spp 4"
            echo "$s $r --shadows map"
            echo "$s $r --shadows map --shadow-map-size 64 --shadow-bias 0"
            echo "$s $r --shadows none"
            echo "$s $r --interpolation gouraud"
            echo "$s $r --interpolation flat"
            echo "$s $r --msaa 4"
            echo "$s $r --forward"
            echo "$s $r --affine --view uv"
            echo "$s $r --bump 0.01"
        done
    done
}

render_all() {
    local bin=$1 out=$2
    mkdir -p "$out"
    local i=0
    while read -r scene renderer opts; do
        i=$((i + 1))
        # shellcheck disable=SC2086
        "$bin" render "$scene" --renderer "$renderer" $opts --width 96 --height 64 \
            -o "$out/$i.exr" 2> "$out/$i.err" || echo "failed" >> "$out/$i.err"
        echo "$scene $renderer $opts" > "$out/$i.case"
        # shellcheck disable=SC2086
        "$bin" pixel "$scene" 48 30 --renderer "$renderer" $opts --width 96 --height 64 --json \
            > "$out/$i.pixel.json" 2>/dev/null || true
    done
}

# SKIP (an extended regular expression) leaves out the cases it matches, e.g.
# SKIP='^bunny (raytrace:brute|rasterize:naive) ' for a quicker check that
# still runs every other scene under those renderers.
cases "$work/pinhole-base" | grep -Ev "${SKIP:-^$}" > "$work/cases.txt"
cases "$work/pinhole-new" | grep -Ev "${SKIP:-^$}" > "$work/cases-new.txt"
if ! cmp -s "$work/cases.txt" "$work/cases-new.txt"; then
    echo "note: the lists of scenes, renderers or views differ; comparing the base's list"
    diff "$work/cases.txt" "$work/cases-new.txt" | head -20 || true
fi
n=$(wc -l < "$work/cases.txt")
echo "rendering $n cases with each binary ..."
base_out="$work/base"
if [ -n "${BASE_RENDERS:-}" ]; then
    base_out=$BASE_RENDERS
    if [ ! -e "$base_out/done" ] || ! cmp -s "$base_out/cases.txt" "$work/cases.txt"; then
        rm -rf "$base_out"
        render_all "$work/pinhole-base" "$base_out" < "$work/cases.txt"
        cp "$work/cases.txt" "$base_out/cases.txt"
        touch "$base_out/done"
    fi
    render_all "$work/pinhole-new" "$work/new" < "$work/cases.txt"
else
    render_all "$work/pinhole-base" "$base_out" < "$work/cases.txt" &
    render_all "$work/pinhole-new" "$work/new" < "$work/cases.txt"
    wait
fi

differ=0
for f in "$base_out"/*.case; do
    i=$(basename "$f" .case)
    what=$(cat "$f")
    for ext in exr pixel.json; do
        a="$base_out/$i.$ext" b="$work/new/$i.$ext"
        if [ -e "$a" ] || [ -e "$b" ]; then
            if ! cmp -s "$a" "$b"; then
                echo "DIFFERS ($ext): $what"
                differ=$((differ + 1))
            fi
        fi
    done
    # Progress lines ("rendering 75.0%, 10 s elapsed ...") depend on the
    # machine's speed, not on the image: they are left out of the comparison.
    if ! cmp -s <(grep -v '^rendering' "$base_out/$i.err") <(grep -v '^rendering' "$work/new/$i.err"); then
        echo "stderr differs: $what"
        differ=$((differ + 1))
    fi
done
exr=$(ls "$base_out"/*.exr 2>/dev/null | wc -l)
echo "$n cases, $exr images from the base; $differ differences"
[ "$differ" -eq 0 ]
