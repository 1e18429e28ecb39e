#!/usr/bin/env bash
# Retrains the default vocabulary, data/vocabulary/plslam_orb_k10_l4.plvoc (README: place
# recognition). Training data: 300 frames each of the office, street (KITTI preset) and corridor
# scenes rendered with seed 101 (evaluation sequences use other seeds), plus the real excerpts of
# ../shared/data where they are present. Deterministic: the same inputs give the same file.
#   usage: scripts/train-vocabulary.sh [BUILD_DIR] [OUT_FILE]
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${1:-build}
OUT=${2:-data/vocabulary/plslam_orb_k10_l4.plvoc}
SHARED=${PLSLAM_SHARED_DIR:-../shared}
PLSLAM="$BUILD_DIR/plslam"
[ -x "$PLSLAM" ] || { echo "train-vocabulary: no $PLSLAM; build first" >&2; exit 2; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$PLSLAM" synth --scene office --frames 300 --seed 101 --out "$WORK/office101"
"$PLSLAM" synth --scene street --preset kitti --frames 300 --seed 101 --out "$WORK/street101"
"$PLSLAM" synth --scene corridor --frames 300 --seed 101 --out "$WORK/corridor101"
datasets=("$WORK/office101" "$WORK/street101" "$WORK/corridor101")
for real in kitti/sequences/06 kitti/sequences/01 euroc/V1_01_easy_micro; do
  if [ -d "$SHARED/data/$real" ]; then datasets+=("$SHARED/data/$real"); else echo "train-vocabulary: no $SHARED/data/$real, left out"; fi
done
# k = 10, L = 4: up to 10^4 words for the ~1.5 million descriptors of these ~1100 images, about
# 150 per word, so every word's IDF is estimated from many images (src/plslam/place/vocabulary_training.h).
"$PLSLAM" vocab train "${datasets[@]}" --k 10 --levels 4 --seed 1 --out "$OUT"
