#!/usr/bin/env bash
# Trains the default ORB vocabulary (k=10, L=5, tf-idf) from the shared images into a cache file,
# unless that file already exists and loads. Usage: scripts/train_vocab.sh [OUT]
#   OUT              default $BUILD_DIR/vocab/orb_k10_l5.vocab
#   BUILD_DIR        build folder holding the edgeslam binary (default: build)
#   EDGESLAM_SHARED  folder holding datasets/ (default: ../shared next to the repository)
#   VOCAB_THREADS    training threads (default: all hardware threads)
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${BUILD_DIR:-build}"
case "$build_dir" in /*) ;; *) build_dir="$repo/$build_dir" ;; esac
binary="$build_dir/edgeslam"
out="${1:-$build_dir/vocab/orb_k10_l5.vocab}"
shared="${EDGESLAM_SHARED:-$repo/../shared}"
threads="${VOCAB_THREADS:-0}"

if [ ! -x "$binary" ]; then
  echo "train_vocab: $binary not found; build first (make build)" >&2
  exit 1
fi
if [ -f "$out" ] && "$binary" vocab info "$out" > /dev/null 2>&1; then
  echo "train_vocab: $out is up to date"
  exit 0
fi
if [ -f "$out" ]; then
  echo "train_vocab: $out does not load; training it again" >&2
fi

datasets="$shared/datasets"
sources=(
  "$datasets/7scenes-redkitchen-1000"
  "$datasets/kitti07-160/image_0"
  "$datasets/tum-fr2desk-20/rgb"
)
for source in "${sources[@]}"; do
  if [ ! -d "$source" ]; then
    echo "train_vocab: missing $source (set EDGESLAM_SHARED to the folder holding datasets/)" >&2
    exit 1
  fi
done

echo "train_vocab: training $out from ${sources[*]}"
"$binary" vocab train --images "${sources[@]}" --out "$out" --k 10 --levels 5 --features 1000 \
  --threads "$threads" --seed 0
"$binary" vocab info "$out"
