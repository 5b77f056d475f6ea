#!/bin/bash
# One run of a training cycle as the T-shirt's last (docs/training-log.md "The T-shirt's cycle on
# t99, two seeds" and "The T-shirt under 1.5 cm"): GarNet-Local for GARMENT on DATA's
# training drapes, every drape, from the network START (copied to DIR/last.garnet when DIR
# holds no checkpoint yet; a model file has no optimiser state, so Adam starts afresh),
# LR along a cosine to 1e-6 at epoch EPOCHS, batch 1 on one thread, every epoch kept.
# Resumable: run it again and it goes on from DIR's mid-epoch or last checkpoint. Run it
# once per core with another SEED, from the repository root, then judge the runs with
# scripts/judge_cycle.sh. Arguments after DIR go to `garnet train` as they are (say
# `--vertex-power 1 --vertex-weight 2` for a network trained with the squared L_vertex).
# Usage:
#   nohup scripts/cycle.sh GARMENT DATA START EPOCHS LR SEED DIR [TRAIN_ARG...] >> DIR.log 2>&1 &
# The T-shirt's cycle of sessions 45-51 (shipped: the mean of both runs' epoch 126), from
# the T-shirt of 124 epochs (`git show 78e9d22:models/tshirt-local.garnet > START`):
#   nohup scripts/cycle.sh tshirt out/standard-x9-t99-lbs START 126 5.5e-6 4 \
#     out/runs/tshirt-c9 >> out/runs/tshirt-c9.log 2>&1 &
#   nohup scripts/cycle.sh tshirt out/standard-x9-t99-lbs START 126 5.5e-6 5 \
#     out/runs/tshirt-c9b >> out/runs/tshirt-c9b.log 2>&1 &
set -e
if [ $# -lt 7 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
GARMENT=$1 DATA=$2 START=$3 EPOCHS=$4 LR=$5 SEED=$6 DIR=$7
shift 7
mkdir -p "$DIR"
[ -f "$DIR/last.garnet" ] || [ -f "$DIR/mid-epoch.garnet" ] || cp "$START" "$DIR/last.garnet"
RAYON_NUM_THREADS=1 exec ./target/release/garnet train --data "$DATA" \
  --garment "$GARMENT" --variant local --batch 1 --grad-clip 200 --out "$DIR" --resume \
  --keep-epochs --epochs "$EPOCHS" --lr "$LR" --cosine-to 1e-6 --seed "$SEED" "$@"
