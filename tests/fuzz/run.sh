#!/usr/bin/env bash
# Builds the reader fuzz targets with clang (libFuzzer + ASan + UBSan) in build-fuzz/ and
# runs each for SECONDS. Fails if any target finds a crash, a sanitizer report, a leak, a
# timeout or an oversized allocation; prints one summary line per target.
#
#   tests/fuzz/run.sh 60
#
# The committed seeds in tests/fuzz/corpus/<target>/ are read but never written: new
# inputs go to build-fuzz/fuzz-corpus/<target>/ and crashes to build-fuzz/fuzz-artifacts/.
set -euo pipefail

seconds=${1:?usage: tests/fuzz/run.sh SECONDS}
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$root/build-fuzz
targets=(ply xyz off obj)

if [ ! -f "$build/build.ninja" ]; then
  CC=clang CXX=clang++ meson setup "$build" "$root" -Dfuzz=true -Dtests=false \
    -Db_lundef=false -Db_sanitize=address,undefined -Dbuildtype=debugoptimized >/dev/null
fi
ninja -C "$build" "${targets[@]/#/tests/fuzz/fuzz_}" >/dev/null

failed=0
for t in "${targets[@]}"; do
  work=$build/fuzz-corpus/$t
  artifacts=$build/fuzz-artifacts/$t
  log=$build/fuzz-$t.log
  mkdir -p "$work" "$artifacts"
  # A single allocation over 256 MB is a finding: inputs are at most 64 KB, so only a
  # trusted header count could ask for that much.
  if "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len=65536 -timeout=10 \
      -rss_limit_mb=2048 -malloc_limit_mb=256 -print_final_stats=1 \
      -artifact_prefix="$artifacts/" "$work" "$root/tests/fuzz/corpus/$t" >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    failed=1
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n1 | cut -d' ' -f2)
  echo "fuzz_$t: $result, ${runs:-?} runs in ${seconds}s, coverage ${cov:-?} edges, corpus $(ls "$work" | wc -l) files (log: $log)"
  if [ "$result" = FAILED ]; then
    grep -m5 -E 'ERROR|runtime error|SUMMARY|Test unit written' "$log" | sed 's/^/    /' || true
  fi
done
exit $failed
