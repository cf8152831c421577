#!/usr/bin/env bash
# Regenerates the seed corpora in fuzz/corpus/ (committed; run this only to change them).
# Files that fuzzing found interesting are added beside the seeds by scripts/fuzz.sh --merge.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
g++ -std=c++20 -O1 -o "$out/make_seeds" fuzz/tools/make_seeds.cpp $(pkg-config --cflags --libs spng) -ljpeg
"$out/make_seeds" fuzz/corpus
find fuzz/corpus -type f | sort | xargs ls -l | awk '{print $5, $9}'
# The gltf target's seeds, written by the tests' glTF writer (needs the release build's library
# for its PNG encoder: cmake --build --preset release --target softrast).
g++ -std=c++20 -O1 -Iinclude -Itests -o "$out/make_gltf_seeds" fuzz/tools/make_gltf_seeds.cpp \
  build/release/libsoftrast.a $(pkg-config --libs spng stb) -ljpeg -lz -lpthread
"$out/make_gltf_seeds" fuzz/corpus/gltf
# fuzz/corpus/batch/seed_*.jsonl (jobs files of `softrast batch`) are written by hand.
