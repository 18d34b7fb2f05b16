#!/bin/sh
# Regenerates screenshots/*.png: the viewer (`pinhole --screenshot`) in a real
# window under Xvfb with Mesa's software OpenGL, on each built-in scene, with
# each renderer family, with the panels open, and the visual-debugging tools
# (debug views with their legends, the pixel inspector with the selected
# pixel's rays drawn, pixel-level zoom, the vertex overlay).
# Usage: scripts/screenshots.sh [PATTERN]  (only shots whose name contains PATTERN)
# Needs: xvfb-run (apt-get install xvfb libgl1-mesa-dri).
set -eu
cd "$(dirname "$0")/.."
cargo build --release --quiet
bin=target/release/pinhole
out=screenshots
mkdir -p "$out"

only=${1:-}
shot() { # NAME SCENE [VAR=VALUE...]
    name=$1; scene=$2; shift 2
    case "$name" in *"$only"*) ;; *) return 0 ;; esac
    env LIBGL_ALWAYS_SOFTWARE=1 "$@" xvfb-run -a -s "-screen 0 1280x800x24" \
        "$bin" --screenshot "$out/$name.png" "$scene" >/dev/null
    echo "$out/$name.png"
}

# Each built-in scene with the default renderer and panels.
for scene in $("$bin" list | awk '/^built-in scenes:/ {s = 1; next} /^[^ ]/ {s = 0} s && NF {print $1}'); do
    shot "scene-$scene" "$scene"
done
# Each renderer family on the same scene.
shot renderer-raytrace teapot PINHOLE_RENDERER=raytrace PINHOLE_PANELS=shading
shot renderer-rasterize teapot PINHOLE_RENDERER=rasterize PINHOLE_PANELS=shading
shot renderer-raytrace-brute one-triangle PINHOLE_RENDERER=raytrace:brute PINHOLE_PANELS=shading
# Panels open: camera and materials; a debug view.
shot panel-camera-materials spheres PINHOLE_PANELS=camera,materials
shot view-barycentric one-triangle PINHOLE_VIEW=barycentric PINHOLE_PANELS=shading
shot view-normal bunny PINHOLE_VIEW=normal PINHOLE_PANELS=lights
shot view-mip textures PINHOLE_VIEW=mip PINHOLE_PANELS=shading
# CGPP Figure 15.2: the gamma test pattern with gamma off and on.
shot gi-path cornell-gi PINHOLE_GI=path PINHOLE_SPP=16 PINHOLE_PANELS=shading
shot gamma-off test-pattern PINHOLE_GAMMA=off PINHOLE_PANELS=shading
shot gamma-on test-pattern PINHOLE_GAMMA=on PINHOLE_PANELS=shading
# Debug views with their legends.
shot view-depth teapot PINHOLE_VIEW=depth PINHOLE_PANELS=none
shot view-zbuffer teapot PINHOLE_VIEW=zbuffer PINHOLE_PANELS=none
shot view-cost bunny PINHOLE_VIEW=cost PINHOLE_PANELS=none
shot view-id spheres PINHOLE_VIEW=id PINHOLE_PANELS=none
shot view-diff teapot PINHOLE_RENDERER=rasterize PINHOLE_VIEW=diff PINHOLE_PANELS=none
shot view-vertices teapot PINHOLE_VERTICES=on PINHOLE_PANELS=none
# The inspector on a selected pixel: a ground point whose shadow ray the
# triangle blocks (red, ending at the blocker); the same zoomed to pixel
# level; the rasterizer's fragment history where the two-sided triangle's
# front and back faces cover the same pixel.
shot inspector-raytrace triangle-ground PINHOLE_SELECT=420,400 PINHOLE_PANELS=none
shot inspector-path cornell-gi PINHOLE_GI=path PINHOLE_SPP=1 PINHOLE_SELECT=250,330 PINHOLE_PANELS=none
shot inspector-zoom triangle-ground PINHOLE_SELECT=420,400 PINHOLE_ZOOM=12 PINHOLE_PANELS=none
shot inspector-rasterize triangle-ground PINHOLE_RENDERER=rasterize PINHOLE_SELECT=500,380 PINHOLE_PANELS=none
# The Compare window after measuring every method on the Cornell box.
shot compare-cornell-gi cornell-gi PINHOLE_COMPARE=on PINHOLE_PANELS=none
# A|B: path-traced indirect light (A) against the rasterizer's direct light (B).
shot split-wipe cornell-gi PINHOLE_SPLIT=rasterize PINHOLE_GI=path PINHOLE_SPP=16 PINHOLE_PANELS=none
# The gallery in the viewer: z-pass counting with the eye inside a shadow volume.
shot gallery-zpass stress-zpass PINHOLE_GALLERY=zpass-eye-in-shadow PINHOLE_PANELS=shading
# The wireframe view (DDA lines over the shaded image) and stencil shadow volumes.
shot view-wireframe teapot PINHOLE_VIEW=wireframe PINHOLE_PANELS=shading
