#!/usr/bin/env bash
# Regenerates every image of docs/ and of the README from a build:
#   docs/images/pipeline/   the figures of the pipeline chapters (docs/pipeline/*.md)
#   docs/images/gallery/    the README's gallery: the real models, and the live viewer
#   docs/images/debug_*.png the README's debug views (the demo scene)
#   docs/images/*_after.png the README's "what the command line shows" (docs/images/make_images.sh)
# Usage: docs/make_docs_images.sh [BUILD_DIR] [OLD_SOFTRAST]
#   BUILD_DIR: a release build of this tree (build/release), with softrast and
#   tools/softrast_docs_figures built (cmake --build --preset release --target softrast_cli
#   softrast_docs_figures). OLD_SOFTRAST: passed on to docs/images/make_images.sh for its
#   "before" images (skipped without it).
# The models are read from ../shared/models (MODELS=... to change); they are not copied into the
# repository, only the images. The viewer's pictures need Xvfb and xdotool (skipped, with a
# message, without them).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:-$here/../build/release}" && pwd)
old=${2:-}
softrast=$build/softrast
figures=$build/tools/softrast_docs_figures
models=${MODELS:-$here/../../shared/models}
models=$(cd "$models" && pwd)
for f in "$softrast" "$figures"; do
  [ -x "$f" ] || { echo "make_docs_images.sh: $f is missing; build it first" >&2; exit 1; }
done
tmp=$(mktemp -d)
xvfb= viewer=
cleanup() {  # the viewer and Xvfb, if a step failed while they ran
  [ -n "$viewer" ] && kill "$viewer" 2>/dev/null
  [ -n "$xvfb" ] && kill "$xvfb" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
pipeline=$here/images/pipeline
gallery=$here/images/gallery
mkdir -p "$pipeline" "$gallery"

diablo=$models/diablo3_pose/diablo3_pose.obj
diablo_tex=$models/diablo3_pose/diablo3_pose_diffuse.tga
r() { "$softrast" render "$@" -q --threads 2; }

# The African head with its eyes (inner part), and diablo, each with an MTL naming its diffuse
# map, so that the viewer (which has no --texture) and a multi-file render show the textures.
mkdir -p "$tmp/head" "$tmp/diablo"
for part in african_head african_head_eye_inner; do
  { echo "mtllib $part.mtl"; echo "usemtl skin"; cat "$models/african_head/$part.obj"; } \
    >"$tmp/head/$part.obj"
  printf 'newmtl skin\nKd 1 1 1\nmap_Kd %s\n' "$models/african_head/${part}_diffuse.tga" \
    >"$tmp/head/$part.mtl"
done
{ echo "mtllib diablo3_pose.mtl"; echo "usemtl skin"; cat "$diablo"; } >"$tmp/diablo/diablo3_pose.obj"
printf 'newmtl skin\nKd 1 1 1\nmap_Kd %s\n' "$diablo_tex" >"$tmp/diablo/diablo3_pose.mtl"
head=("$tmp/head/african_head.obj" "$tmp/head/african_head_eye_inner.obj")

echo "== pipeline figures (tools/docs_figures.cpp)"
"$figures" "$pipeline"

echo "== pipeline figures (softrast render)"
# 1. Transforms and cameras: the same framing with a narrow and a wide field of view, and an
# orthographic box (the camera placed by hand: --eye cannot be framed automatically).
r "$diablo" --texture "$diablo_tex" --fov 15 --size 300x300 -o "$pipeline/camera_fov15.png"
r "$diablo" --texture "$diablo_tex" --fov 90 --size 300x300 -o "$pipeline/camera_fov90.png"
r "$diablo" --texture "$diablo_tex" --ortho -1.1,1.1,-1.1,1.1 --eye 0,0,5 --target 0,0,0 \
  --near 1 --far 10 --size 300x300 -o "$pipeline/camera_ortho.png"
# 6. The depth buffer.
r "$diablo" --shader depth --size 300x300 -o "$pipeline/depth_view_diablo.png"
r "$diablo" --texture "$diablo_tex" --size 300x300 -o "$pipeline/depth_less_diablo.png"
r "$diablo" --texture "$diablo_tex" --depth off --size 300x300 -o "$pipeline/depth_off_diablo.png"
# 7. Tiles, binning and threads.
r "$diablo" --texture "$diablo_tex" --debug tiles --size 640x480 -o "$pipeline/debug_tiles_diablo.png"
r "$diablo" --debug overdraw --size 400x400 -o "$pipeline/debug_overdraw_diablo.png"
r "$diablo" --debug overdraw --cull back --size 400x400 -o "$pipeline/debug_overdraw_diablo_cull.png"
# The cost view on the demo scene (textured, a floor over the whole image: more work per tile
# than diablo's few thousand triangles), one thread, so that each tile is timed alone.
"$softrast" render --debug cost --size 640x480 --threads 1 -q -o "$pipeline/debug_cost_demo.png"

echo "== README debug views (the demo scene)"
for view in tiles overdraw cost triangles; do
  r --debug "$view" --size 320x240 -o "$here/images/debug_$view.png"
done

echo "== gallery"
r "${head[@]}" --size 400x400 -o "$gallery/head.png"
r "${head[@]}" --azimuth 35 --elevation 10 --size 400x400 -o "$gallery/head_three_quarter.png"
r "$diablo" --texture "$diablo_tex" --size 400x400 -o "$gallery/diablo.png"
r "$diablo" --texture "$diablo_tex" --view back --azimuth 150 --elevation 15 --size 400x400 \
  -o "$gallery/diablo_back.png"
r "$diablo" --shader gouraud --wireframe --color 0.8,0.8,0.8 --size 400x400 \
  -o "$gallery/diablo_wire.png"
r "$diablo" --shader normals --size 400x400 -o "$gallery/diablo_normals.png"

echo "== the viewer (softrast view under Xvfb)"
if command -v Xvfb >/dev/null && command -v xdotool >/dev/null; then
  exec 3>"$tmp/display"
  Xvfb -displayfd 3 -screen 0 1280x1024x24 -nolisten tcp </dev/null >/dev/null 2>&1 &
  xvfb=$!
  for _ in $(seq 50); do [ -s "$tmp/display" ] && break; sleep 0.1; done
  export DISPLAY=:$(head -1 "$tmp/display")
  shot() {  # shot NAME: press P, wait for the screenshot (the frame as shown), keep it as NAME
    local saved=$tmp/view/softrast_view_001.png
    xdotool key --window "$win" p
    for _ in $(seq 100); do
      [ -f "$saved" ] && break
      sleep 0.1
    done
    [ -f "$saved" ] || { echo "make_docs_images.sh: the viewer saved no screenshot" >&2; exit 1; }
    mv "$saved" "$gallery/$1"
    echo "$1: window title: $(xdotool getwindowname "$win")"
  }
  mkdir -p "$tmp/view"
  (cd "$tmp/view" && exec env SDL_VIDEODRIVER=x11 SDL_RENDER_DRIVER=software \
    "$softrast" view "$tmp/diablo/diablo3_pose.obj" --size 640x480 --threads 2 -q \
    </dev/null >/dev/null 2>&1) &
  viewer=$!
  win=$(xdotool search --sync --onlyvisible --pid "$viewer" | head -1)
  xdotool windowfocus --sync "$win"
  sleep 0.5
  # A left drag orbits the model a little to the right and from above.
  xdotool mousemove --window "$win" 320 240 mousedown 1 mousemove --window "$win" 250 200 \
    mouseup 1 click 4 click 4  # orbit, then two wheel notches closer
  sleep 0.5
  shot viewer_orbit.png
  xdotool key --window "$win" w  # the wireframe overlay
  sleep 0.5
  shot viewer_wireframe.png
  xdotool key --window "$win" w d d  # overlay off, debug view: tiles, then overdraw
  sleep 0.5
  shot viewer_overdraw.png
  xdotool key --window "$win" q 2>/dev/null || true  # the window may go before the key-up
  wait "$viewer" || true
  viewer=
  kill "$xvfb" 2>/dev/null || true
  wait "$xvfb" 2>/dev/null || true
  xvfb=
else
  echo "Xvfb or xdotool missing: the viewer's pictures are left as they are"
fi

echo "== README 'what the command line shows' (docs/images/make_images.sh)"
bash "$here/images/make_images.sh" "$softrast" $old
echo "done"
