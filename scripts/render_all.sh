#!/usr/bin/env bash
# scripts/render_all.sh FOLDER [OUT]: renders every model file under FOLDER (OBJ, PLY, STL, glTF,
# GLB, any case) with `softrast render` and no flag but the size, one PNG each in OUT (default
# /tmp/softrast_render_all), and prints one line per file: the exit code, the seconds taken, the
# file, and the first line softrast printed on stderr besides its progress (the error, or the first
# warning). Ends with the count of each exit code. A look at how the renderer meets files it was
# not written against, for example Debian's assimp test models:
#   apt-get install -y assimp-testmodels && scripts/render_all.sh /usr/share/assimp/models
# Each render is limited to 60 seconds (exit code 124 past it). Not part of the tests.
set -uo pipefail
[[ $# -ge 1 && $# -le 2 ]] || { echo "usage: scripts/render_all.sh FOLDER [OUT]" >&2; exit 2; }
folder=$(realpath "$1") || exit 2
out=$(realpath -m "${2:-/tmp/softrast_render_all}") || exit 2
cd "$(dirname "$0")/.." || exit 2
bin=$(realpath -m "${SOFTRAST:-build/release/softrast}")
[[ -x $bin ]] || { echo "render_all.sh: $bin not found (build first, or set SOFTRAST)" >&2; exit 2; }
mkdir -p "$out"
err=$(mktemp)
trap 'rm -f "$err"' EXIT
codes=()
while IFS= read -r -d '' file; do
  name=${file#"$folder"}
  name=${name#/}
  start=$(date +%s%N)
  timeout 60 "$bin" render "$file" --size 320x240 -o "$out/${name//\//_}.png" >/dev/null 2>"$err"
  code=$?
  ms=$((($(date +%s%N) - start) / 1000000))
  first=$(grep -v '^loaded \|^rendered \|^wrote ' "$err" | head -1)
  printf '%-3s %6d ms  %s  %s\n' "$code" "$ms" "$name" "$first"
  codes+=("$code")
done < <(find "$folder" -type f \( -iname '*.obj' -o -iname '*.ply' -o -iname '*.stl' -o \
  -iname '*.gltf' -o -iname '*.glb' \) -print0 | sort -z)
echo "files by exit code:"
printf '%s\n' "${codes[@]}" | sort | uniq -c
