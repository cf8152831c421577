#!/usr/bin/env bash
# Side by side with llvmpipe: the same SCENES.md scene, size and thread count, alternating runs,
# one median_ms line per run. Usage: tools/reference/side_by_side.sh [SCENES_DIR] [BUILD_DIR]
# (scenes: python3 ../shared/bench/gen_scenes.py /tmp/scenes; build with the reference on).
set -euo pipefail
S=${1:-/tmp/scenes}
B=${2:-build/release}
R=$B/softrast
G=$B/tools/reference/glref
THREADS=${THREADS:-2}
run() {
  local name=$1
  shift
  for _ in 1 2 3; do
    echo "$name softrast $("$R" "$@" --threads "$THREADS" -q | grep -o '"median_ms":[0-9.]*')"
    echo "$name llvmpipe $(LP_NUM_THREADS=$THREADS "$G" "$@" -q | grep -o '"median_ms":[0-9.]*')"
  done
}
run spheres_gouraud "$S/spheres_1m.obj" --size 1920x1080 --eye 0,0,21.73 --target 0,0,0 --up 0,1,0 \
  --fov 45 --near 1 --far 100 --cull back --frames 10 --shader gouraud
run overdraw_gouraud "$S/overdraw.obj" --size 1920x1080 --eye 0,0,10 --target 0,0,0 --up 0,1,0 \
  --fov 45 --near 1 --far 100 --cull back --frames 6 --shader gouraud
run quad_grid_texture "$S/quad_grid.obj" --size 1920x1080 --eye 0,6,6 --target 0,0,-1 --up 0,1,0 \
  --fov 50 --near 0.5 --far 100 --cull back --frames 40 --texture "$S/checker.png" --shader texture
