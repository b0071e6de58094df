#!/usr/bin/env bash
# Runs every libFuzzer harness of $FUZZ_DIR for $FUZZ_SECONDS seconds (`make fuzz`), on a corpus
# that grows across runs, seeded from real messages and files (fuzz_seeds, rewritten each run). Prints the
# executions of each; exits 1 when a harness found a crash (its input is in fuzz-crashes/).
# FUZZ_RUNS=N stops each harness after N executions instead (a campaign: FUZZ_SECONDS is then the
# most each may take).
set -uo pipefail
FUZZ_DIR=${FUZZ_DIR:-build-asan}
FUZZ_SECONDS=${FUZZ_SECONDS:-20}
FUZZ_RUNS=${FUZZ_RUNS:--1}
FUZZ_HARNESSES=${FUZZ_HARNESSES:-}  # names (fuzz_camera_yaml ...) to run only these
SHARED=${EDGESLAM_SHARED:-$(cd "$(dirname "$0")/../.." && pwd)/shared}
seeds="$FUZZ_DIR/fuzz-seeds"
rm -rf "$seeds"
"$FUZZ_DIR/tests/fuzz/fuzz_seeds" "$seeds" "$SHARED" || exit 1
mkdir -p "$FUZZ_DIR/fuzz-corpus" "$FUZZ_DIR/fuzz-crashes" "$FUZZ_DIR/fuzz-logs"
failed=0
printf '%-24s %12s %10s %s\n' harness executions exec/s result
for harness in "$FUZZ_DIR"/tests/fuzz/fuzz_*; do
  name=$(basename "$harness")
  [ "$name" = fuzz_seeds ] && continue
  if [ -n "$FUZZ_HARNESSES" ] && [[ " $FUZZ_HARNESSES " != *" $name "* ]]; then continue; fi
  [ -x "$harness" ] || continue
  corpus="$FUZZ_DIR/fuzz-corpus/$name"
  mkdir -p "$corpus" "$seeds/$name"
  log="$FUZZ_DIR/fuzz-logs/$name.log"
  max_len=65536
  [ "$name" = fuzz_map_store ] && max_len=262144  # a whole (small) database file
  timeout -k 10 $((FUZZ_SECONDS + 120)) "$harness" "$corpus" "$seeds/$name" \
    -max_total_time="$FUZZ_SECONDS" -runs="$FUZZ_RUNS" -max_len=$max_len -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$FUZZ_DIR/fuzz-crashes/$name-" >"$log" 2>&1
  status=$?
  executions=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  rate=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  result=clean
  if [ $status -ne 0 ]; then
    result="FAILED (exit $status, see $log)"
    failed=1
  fi
  printf '%-24s %12s %10s %s\n' "$name" "${executions:-?}" "${rate:-?}" "$result"
done
rm -rf /dev/shm/edgeslam_fuzz_* 2>/dev/null
exit $failed
