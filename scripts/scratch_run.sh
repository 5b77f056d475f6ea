#!/bin/bash
# One network trained from scratch with the recipe of the shipped T-shirt Global and Naive
# (docs/training-log.md "Shipped with the extensions", session 20), on every training drape of DATA
# (session 21: the filter to clean drapes cost more than it saved; pass --at-rest
# --max-strain 5 for the T-shirt's own filter): VARIANT for GARMENT with
# both extensions (configs/contact-rest.json), batch 1, gradients clipped to 200, one thread,
# one epoch at 3e-4, then 3e-4 along a cosine to 1e-5 at epoch EPOCHS, step by step (a
# schedule of a few epochs over a large set would otherwise end a rung above 1e-5; the
# T-shirt's 30 short epochs went epoch by epoch). Resumable: run it again and it goes on
# from DIR's mid-epoch or last checkpoint. Arguments after DIR go to both `garnet train`
# calls as they are. Run from the repository root:
#   nohup scripts/scratch_run.sh GARMENT VARIANT DATA EPOCHS DIR [TRAIN_ARG...] >> DIR.log 2>&1 &
# The sweater's Global (session 54) and the jeans' Naive (session 55) as shipped:
#   scripts/scratch_run.sh sweater global out/standard-x9-sw54-lbs 4 out/runs/sweater-global
#   scripts/scratch_run.sh jeans naive out/standard-lbs 30 out/runs/jeans-naive \
#     --at-rest --max-strain 5
set -e
if [ $# -lt 5 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
GARMENT=$1 VARIANT=$2 DATA=$3 EPOCHS=$4 DIR=$5
shift 5
mkdir -p "$DIR"
train() {
  RAYON_NUM_THREADS=1 ./target/release/garnet train --data "$DATA" --garment "$GARMENT" \
    --variant "$VARIANT" --config configs/contact-rest.json --batch 1 --grad-clip 200 \
    --out "$DIR" --resume "$@"
}
# The first epoch at a constant rate, unless metrics.csv already has it: a finished run's
# checkpoint must not be resumed without its schedule, which would restart the cosine.
if [ "$(tail -n +2 "$DIR/metrics.csv" 2>/dev/null | wc -l)" -lt 1 ]; then
  train --epochs 1 --lr 3e-4 "$@"
fi
train --epochs "$EPOCHS" --lr 3e-4 --cosine-to 1e-5 --cosine-per-step "$@"
