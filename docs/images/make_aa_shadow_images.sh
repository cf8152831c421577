#!/usr/bin/env bash
# Renders the README's anti-aliasing and shadow images into docs/images/: the African head
# without and with 4x multisampling (a crop enlarged 3x, side by side), and the diablo model on
# the floor of ../shared/models without and with --shadows.
# Usage: docs/images/make_aa_shadow_images.sh [SOFTRAST]   (default build/release/softrast)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
softrast=${1:-$here/../../build/release/softrast}
models=${MODELS:-$here/../../../shared/models}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
head=$models/african_head/african_head.obj

# Anti-aliasing: the same frame at 1 and 4 samples per pixel; the crop is the right cheek and ear
# against the background.
for n in 1 4; do
  "$softrast" render "$head" --texture "$models/african_head/african_head_diffuse.tga" \
    --size 400x400 --azimuth 30 --msaa $n -q -o "$tmp/head_msaa$n.png"
done
python3 "$here/crop_png.py" "$here/msaa_head_crop.png" 250 120 100 100 3 \
  "$tmp/head_msaa1.png" "$tmp/head_msaa4.png"

# Shadows: the posed diablo model standing on the floor, lit from the upper left front.
common=(render "$models/diablo3_pose/diablo3_pose.obj" "$models/floor.obj" --size 360x360
  --view iso --light -1,1.5,1 --msaa 4 -q)
"$softrast" "${common[@]}" -o "$tmp/diablo_plain.png"
"$softrast" "${common[@]}" --shadows -o "$tmp/diablo_shadows.png"
python3 "$here/crop_png.py" "$here/shadows_diablo.png" 0 0 360 360 1 \
  "$tmp/diablo_plain.png" "$tmp/diablo_shadows.png"
