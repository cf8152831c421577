#!/usr/bin/env bash
# Renders the before/after images of the README's "What the command line shows" section into
# docs/images/. The models come from ../shared/models (not copied into the repository); the
# half sphere and the Z-up and multi-part variants are written to a temporary folder.
# Usage: docs/images/make_images.sh [NEW_SOFTRAST] [OLD_SOFTRAST]
#   NEW: this tree's build (build/release/softrast); OLD: a build of main at f844599 (before
#   issue 8's command-line work), for the "before" images. Without OLD those are skipped:
#     git archive f844599 | tar -x -C /tmp/before && cd /tmp/before &&
#     cmake --preset release && cmake --build --preset release --target softrast_cli
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
new=${1:-$here/../../build/release/softrast}
old=${2:-}
models=${MODELS:-$here/../../../shared/models}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out=$here
size="--size 480x270 -q"
head=$models/african_head/african_head.obj
head_tex=$models/african_head/african_head_diffuse.tga

# A half sphere, open at the bottom: single-sided geometry whose inside shows from below.
python3 - "$tmp/half_sphere.obj" <<'PY'
import math, sys
rings, segs = 12, 32
with open(sys.argv[1], "w") as f:
    for i in range(rings + 1):
        t = (math.pi / 2) * i / rings          # 0 at the pole, pi/2 at the rim
        for j in range(segs):
            p = 2 * math.pi * j / segs
            f.write("v %.6f %.6f %.6f\n" % (math.sin(t) * math.cos(p), math.cos(t), math.sin(t) * math.sin(p)))
    for i in range(rings):
        for j in range(segs):
            a = i * segs + j + 1; b = i * segs + (j + 1) % segs + 1
            f.write("f %d %d %d %d\n" % (a, b, b + segs, a + segs))
PY

# The diablo model turned Z-up: (x, y, z) -> (x, -z, y) for positions and normals.
awk '/^v |^vn /{print $1, $2, -$4, $3; next} {print}' \
  "$models/diablo3_pose/diablo3_pose.obj" >"$tmp/diablo_z_up.obj"

# The African head and its eyes, two files, each with its own MTL naming its own diffuse map.
mkdir -p "$tmp/head"
for part in african_head african_head_eye_inner; do
  { echo "mtllib $part.mtl"; echo "usemtl skin"; cat "$models/african_head/$part.obj"; } \
    >"$tmp/head/$part.obj"
  printf 'newmtl skin\nKd 1 1 1\nmap_Kd %s\n' "$models/african_head/${part}_diffuse.tga" \
    >"$tmp/head/$part.mtl"
done

# ONLY=materials renders only the materials section at the end (the images above stay as they
# were rendered for their own section).
if [ "${ONLY:-all}" != materials ]; then
# After: this tree.
# glTF with the pbr shader, chosen without flags (README, "glTF 2.0 and PBR").
$new "$here/../models/pbr_spheres.glb" --size 640x640 -o "$out/pbr_spheres.png"
$new $head --texture "$head_tex" --view back $size -o "$out/head_back_after.png"
$new $head --texture "$head_tex" --view right $size -o "$out/head_side_after.png"
$new "$models/floor.obj" --texture "$models/floor_diffuse.tga" --wireframe $size \
  -o "$out/floor_overlay_after.png"
$new "$tmp/half_sphere.obj" --eye 1,-1.2,2.6 --target 0,0.3,0 $size -o "$out/half_sphere_after.png"
$new "$tmp/head/african_head.obj" "$tmp/head/african_head_eye_inner.obj" --azimuth 25 \
  --elevation 10 $size -o "$out/head_parts_after.png"
diablo_tex=$models/diablo3_pose/diablo3_pose_diffuse.tga
$new "$tmp/diablo_z_up.obj" --texture "$diablo_tex" --up-axis +z --view iso $size \
  -o "$out/z_up_after.png"
$new "$models/diablo3_pose/diablo3_pose.obj" --texture "$diablo_tex" --background 0,0,0,0 --size 160x160 -q -o "$out/thumbnail_transparent.png"

# Before: main at f844599, before issue 8's command-line work (light fixed in world space at
# 0.3,0.5,0.8, back faces culled, the overlay depth-tested with a constant bias, framing of the
# bounding sphere from +z). It has no --light, --view or --edge-color flags.
if [ -n "$old" ]; then
  $old $head --texture "$head_tex" --eye 0,0,-3 $size -o "$out/head_back_before.png"
  $old $head --texture "$head_tex" --eye 3,0,0 $size -o "$out/head_side_before.png"
  $old "$models/floor.obj" --texture "$models/floor_diffuse.tga" --wireframe $size \
    -o "$out/floor_overlay_before.png"
  $old "$tmp/half_sphere.obj" --eye 1,-1.2,2.6 --target 0,0.3,0 $size \
    -o "$out/half_sphere_before.png"
  $old "$tmp/diablo_z_up.obj" --texture "$diablo_tex" $size -o "$out/z_up_before.png"
fi
fi  # ONLY

# Materials (issue 6): the real models with every map by the plain command (the maps of the
# tutorial convention, <model>_diffuse/_spec/_nm_tangent.tga, found beside the OBJ), the same with
# --maps diffuse, a point light, and the demo scene's far floor without and with mipmaps.
hd=$models/african_head
msize="--size 320x320 -q"
$new "$hd/african_head.obj" "$hd/african_head_eye_inner.obj" "$hd/african_head_eye_outer.obj" \
  $msize -o "$out/materials_head.png"
$new "$hd/african_head.obj" "$hd/african_head_eye_inner.obj" "$hd/african_head_eye_outer.obj" \
  --maps diffuse $msize -o "$out/materials_head_diffuse.png"
$new "$models/diablo3_pose/diablo3_pose.obj" $msize -o "$out/materials_diablo.png"
$new "$models/diablo3_pose/diablo3_pose.obj" --maps diffuse $msize \
  -o "$out/materials_diablo_diffuse.png"
$new "$models/diablo3_pose/diablo3_pose.obj" --light-pos 0.6,0.4,0.7 $msize \
  -o "$out/materials_diablo_point.png"
$new "$models/diablo3_pose/diablo3_pose.obj" --srgb $msize -o "$out/materials_diablo_srgb.png"
$new --filter bilinear --size 480x270 -q -o "$out/demo_floor_bilinear.png"
$new --filter trilinear --size 480x270 -q -o "$out/demo_floor_trilinear.png"
