#!/usr/bin/env bash
# Side by side with llvmpipe: every row of the speed issue's table (the SCENES.md scenes and the
# diablo3_pose model of ../shared/models), the same flags, size and thread count, runs alternating
# between the two renderers; prints one JSON line per row and a table of medians and ratios.
# Usage: tools/reference/side_by_side.sh [SCENES_DIR] [BUILD_DIR]   (THREADS=2 RUNS=3 by default)
# (scenes: python3 ../shared/bench/gen_scenes.py /tmp/scenes; build with the reference on).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
S=${1:-/tmp/scenes}
B=${2:-build/release}
exec python3 "$here/compare_scenes.py" --scenes "$S" --build "$B" --threads "${THREADS:-2}" \
  --runs "${RUNS:-3}" --out "${OUT:-/tmp/side_by_side}"
