#!/usr/bin/env bash
# `make bench`: runs every micro-benchmark executable of the build (BUILD_DIR/bench/*_bench),
# pinned to one core as the client would be.
#   BUILD_DIR   build folder (default: build; or the first argument)
#   BENCH_CPU   core to pin to (default: 0; empty: no pinning)
#   BENCH_OUT   folder for JSON results, one file per executable (default: none)
#   BENCH_FILTER  passed as --benchmark_filter (default: all)
# Extra arguments after the build folder go to every benchmark executable.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${1:-${BUILD_DIR:-build}}"
[[ $# -gt 0 ]] && shift
[[ "$build_dir" = /* ]] || build_dir="$root/$build_dir"
cpu="${BENCH_CPU-0}"

bench_dir="$build_dir/bench"
if [[ ! -d "$bench_dir" ]]; then
  echo "bench: no $bench_dir (build first; Google Benchmark must be installed)" >&2
  exit 1
fi
mapfile -t executables < <(find "$bench_dir" -maxdepth 1 -type f -name '*_bench' -perm -u+x | sort)
if [[ ${#executables[@]} -eq 0 ]]; then
  echo "bench: no *_bench executables in $bench_dir" >&2
  exit 1
fi

pin=()
if [[ -n "$cpu" ]]; then
  if command -v taskset >/dev/null 2>&1; then
    pin=(taskset -c "$cpu")
  else
    echo "bench: taskset not found, running unpinned" >&2
  fi
fi

args=("$@")
[[ -n "${BENCH_FILTER:-}" ]] && args+=("--benchmark_filter=$BENCH_FILTER")
if [[ -n "${BENCH_OUT:-}" ]]; then
  mkdir -p "$BENCH_OUT"
fi

status=0
for exe in "${executables[@]}"; do
  name="$(basename "$exe")"
  echo "== $name ${pin[*]:+(${pin[*]})}"
  out_args=()
  if [[ -n "${BENCH_OUT:-}" ]]; then
    out_args=("--benchmark_out=$BENCH_OUT/$name.json" "--benchmark_out_format=json")
  fi
  if ! "${pin[@]}" "$exe" "${out_args[@]}" "${args[@]}"; then
    echo "bench: $name failed" >&2
    status=1
  fi
done
exit $status
