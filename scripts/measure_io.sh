#!/usr/bin/env bash
# The two input/output figures of the README, as issue 7 defines them:
#  1. the whole process rendering diablo3_pose (textured, phong, 1920x1080, the benchmark's
#     camera) to PNG, and to TGA for comparison: median of 10 runs of wall time and peak RSS
#     (the clock around each run, and /usr/bin/time -f '%M');
#  2. loading the benchmark's spheres_1m.obj (109 MB): MB/s and peak RSS of a process that only
#     loads it (build/release/bench/softrast_model_load), median of 5 loads.
# Usage: bash scripts/measure_io.sh [BUILD_DIR] (default build/release). Needs ../shared/models
# and /tmp/scenes/spheres_1m.obj (python3 ../shared/bench/gen_scenes.py /tmp/scenes).
set -euo pipefail
build=${1:-build/release}
models=$(dirname "$0")/../../shared/models/diablo3_pose
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
flags=(--texture "$models/diablo3_pose_diffuse.tga" --size 1920x1080 --eye 0,0,3 --target 0,0,0
       --up 0,1,0 --fov 45 --near 0.1 --far 100 --cull back -q)
for ext in png tga; do
  for i in $(seq 10); do
    # Wall time to the millisecond from the clock around the run (/usr/bin/time's %e has 10 ms
    # steps), peak RSS from /usr/bin/time.
    # Also the CPU time (user + system), which depends less on what else the machine runs.
    start=$(date +%s%N)
    r=$(/usr/bin/time -f '%M %U %S' "$build/softrast" render "$models/diablo3_pose.obj" \
      "${flags[@]}" -o "$out/diablo3.$ext" 2>&1 >/dev/null | tail -1)
    end=$(date +%s%N)
    echo "$(( (end - start) / 1000000 )) $r"
  done >"$out/times"
  t=$(sort -n "$out/times" | awk '{t[NR] = $1} END {printf "%.3f", (t[5] + t[6]) / 2 / 1000}')
  m=$(sort -n -k2 "$out/times" | awk '{m[NR] = $2} END {printf "%.1f", (m[5] + m[6]) / 2 / 1024}')
  c=$(awk '{print $3 + $4}' "$out/times" | sort -n |
      awk '{c[NR] = $1} END {printf "%.3f", (c[5] + c[6]) / 2}')
  all=$(sort -n "$out/times" | awk '{printf "%s%d", (NR > 1 ? " " : ""), $1}')
  echo "diablo3_pose -> $ext: median $t s wall, $c s CPU, peak RSS median $m MiB" \
    "(10 runs; wall ms sorted: $all)"
done
echo "PNG size: $(stat -c %s "$out/diablo3.png") bytes"
"$build/bench/softrast_model_load" /tmp/scenes/spheres_1m.obj 5 | tail -1
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
