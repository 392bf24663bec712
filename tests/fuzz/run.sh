#!/usr/bin/env bash
# Builds the fuzz targets with clang (libFuzzer + ASan + UBSan) in build-fuzz/ and runs
# each for SECONDS: the readers (ply xyz off obj) and the whole pipeline (pipeline). Fails
# if any target finds a crash, a sanitizer report, a leak, a timeout or an oversized
# allocation; prints one summary line per target.
#
#   tests/fuzz/run.sh 60              # every target
#   tests/fuzz/run.sh 20 pipeline ply  # some
#
# The committed seeds in tests/fuzz/corpus/<target>/ are read but never written: new
# inputs go to build-fuzz/fuzz-corpus/<target>/ and crashes to build-fuzz/fuzz-artifacts/.
set -euo pipefail

seconds=${1:?usage: tests/fuzz/run.sh SECONDS [TARGET...]}
shift
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=$(cd "$root" && mkdir -p "${GMPU_FUZZ_BUILD:-build-fuzz}" && cd "${GMPU_FUZZ_BUILD:-build-fuzz}" && pwd)
targets=(ply xyz off obj pipeline)
[ $# -gt 0 ] && targets=("$@")

if [ ! -f "$build/build.ninja" ]; then
  # The Makefile's build-sanitize configuration, with libFuzzer's coverage instrumentation.
  CC=clang CXX=clang++ meson setup "$build" "$root" -Dfuzz=true -Dtests=false \
    -Db_lundef=false -Db_sanitize=address,undefined -Doptimization=2 -Ddebug=true \
    -Dcpp_args='-fsanitize=fuzzer-no-link -fno-sanitize-recover=all' -Dc_args=-fno-sanitize-recover=all >/dev/null
fi
ninja -C "$build" "${targets[@]/#/tests/fuzz/fuzz_}" >/dev/null
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

failed=0
for t in "${targets[@]}"; do
  work=$build/fuzz-corpus/$t
  artifacts=$build/fuzz-artifacts/$t
  log=$build/fuzz-$t.log
  mkdir -p "$work" "$artifacts"
  # A single allocation over 256 MB is a finding: inputs are at most 64 KB, so only a
  # trusted header count could ask for that much.
  # The pipeline reads at most ~2 KB (200 points). Its runs are held to a CPU budget by the
  # target itself (a busy machine must not make a finding); the wall-clock -timeout here
  # only catches hangs, with a wide margin over that budget.
  max_len=65536 timeout=10
  [ "$t" = pipeline ] && max_len=4096 timeout=300
  if "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len=$max_len -timeout=$timeout \
      -rss_limit_mb=2048 -malloc_limit_mb=256 -print_final_stats=1 \
      -artifact_prefix="$artifacts/" "$work" "$root/tests/fuzz/corpus/$t" >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    failed=1
  fi
  # (|| true: a target that crashes on its first input prints no statistics)
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1 || true)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n1 | cut -d' ' -f2 || true)
  echo "fuzz_$t: $result, ${runs:-?} runs in ${seconds}s, coverage ${cov:-?} edges, corpus $(ls "$work" | wc -l) files (log: $log)"
  if [ "$result" = FAILED ]; then
    grep -m5 -E 'ERROR|runtime error|SUMMARY|Test unit written' "$log" | sed 's/^/    /' || true
  fi
done
exit $failed
