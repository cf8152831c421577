#!/usr/bin/env bash
# scripts/fuzz.sh TARGET MINUTES [--merge]: builds the libFuzzer targets if needed (cmake --preset
# fuzz: clang, ASan, UBSan, in build/fuzz), runs one target for MINUTES at low priority, and
# prints the executions, the coverage (libFuzzer's cov: edges and ft: features) and the crashes.
#   TARGET: obj, png, tga, jpeg, cli_args, batch, geometry, gltf, ply or stl (fuzz/fuzz_entries.hpp says what each does)
#   The run starts from fuzz/corpus/TARGET (the committed seeds) and build/fuzz/corpus/TARGET
#   (what earlier runs found; new inputs go there). Crashes, leaks, timeouts and out-of-memory
#   inputs are written to build/fuzz/crashes/TARGET/; reproduce one with
#   build/fuzz/fuzz/fuzz_TARGET FILE. --merge then adds the inputs that reach new coverage to
#   the committed corpus fuzz/corpus/TARGET (the normal test pass replays it); MINUTES 0 with
#   --merge only merges what earlier runs found.
# Exit status: 0 when the run found no crash, 1 when it did, 2 for a usage error.
set -euo pipefail
cd "$(dirname "$0")/.."

targets="obj png tga jpeg cli_args batch geometry gltf ply stl"
usage() {
  echo "usage: scripts/fuzz.sh TARGET MINUTES [--merge]   (TARGET: ${targets// /, })" >&2
  exit 2
}
[[ $# -ge 2 && $# -le 3 ]] || usage
target=$1 minutes=$2 merge=${3:-}
[[ " $targets " == *" $target "* ]] || usage
[[ -z $merge || $merge == --merge ]] || usage
[[ $minutes =~ ^[0-9]+$ ]] || usage
[[ $minutes -ge 1 || $merge == --merge ]] || usage

build=build/fuzz
if [[ ! -f $build/CMakeCache.txt ]]; then
  cmake --preset fuzz >/dev/null
fi
nice -n 10 cmake --build --preset fuzz --target "fuzz_$target" >/dev/null

binary=$build/fuzz/fuzz_$target
work=$build/corpus/$target
crashes=$build/crashes/$target
log=$build/logs/$target.$(date -u +%Y%m%dT%H%M%SZ).log
mkdir -p "$work" "$crashes" "$(dirname "$log")"
new="" status=0
if [[ $minutes -ge 1 ]]; then
  before=$(find "$crashes" -type f | sort)

  # -rss_limit_mb: a decompression bomb or runaway allocation is a finding, not a machine-wide
  # swap storm; -timeout: an input taking 10 s is a hang. libFuzzer writes new inputs to the first
  # corpus folder only, so the committed seeds stay untouched.
  set +e
  nice -n 15 "$binary" -max_total_time=$((minutes * 60)) -dict="fuzz/dict/$target.dict" \
    -rss_limit_mb=2560 -malloc_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$crashes/" "$work" "fuzz/corpus/$target" >"$log" 2>&1
  status=$?
  set -e

  executions=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  coverage=$(grep -E '^#[0-9]+.*cov: ' "$log" | tail -1 | grep -oE 'cov: [0-9]+ ft: [0-9]+' || true)
  per_second=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' || true)
  after=$(find "$crashes" -type f | sort)
  new=$(comm -13 <(echo "$before") <(echo "$after") | sed '/^$/d')

  echo "target:      $target ($minutes min, log $log)"
  echo "executions:  ${executions:-?} (${per_second:-?}/s)"
  echo "coverage:    ${coverage:-?}"
  echo "corpus:      $(find "$work" -type f | wc -l) inputs in $work"
  if [[ -n $new ]]; then
    echo "crashes:     $(echo "$new" | wc -l) new in $crashes/"
    echo "$new" | sed 's/^/  /'
    grep -E 'ERROR: |SUMMARY: |what\(\): ' "$log" | head -5 | sed 's/^/  /'
  else
    echo "crashes:     0 new ($(echo "$after" | sed '/^$/d' | wc -l) in $crashes/ from earlier runs)"
  fi
fi

if [[ $merge == --merge ]]; then
  # Into the committed corpus, only the inputs of earlier runs that reach coverage it does not
  # (libFuzzer names them by their SHA-1).
  count() { find "fuzz/corpus/$target" -type f | wc -l; }
  had=$(count)
  nice -n 15 "$binary" -merge=1 -rss_limit_mb=2560 -timeout=10 "fuzz/corpus/$target" "$work" \
    >/dev/null 2>&1
  echo "merged:      $(($(count) - had)) inputs added to fuzz/corpus/$target"
fi

[[ -z $new && ( $status -eq 0 ) ]] || exit 1
