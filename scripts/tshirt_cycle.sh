#!/bin/bash
# The T-shirt's next cycle (docs/model.md "The T-shirt's cycle on t99, two seeds"): two
# epochs on all of standard-x9-t99-lbs's training T-shirts from the shipped T-shirt (whose
# file records 124 epochs, before and since session 50 shipped this cycle's first epoch; a
# model file has no optimiser state, so Adam starts afresh), 5.5e-6 along a cosine
# to 1e-6, batch 1 on one thread, every epoch kept. Resumable: run it again and it goes on
# from DIR's mid-epoch or last checkpoint. Run it once per core with another seed, from the
# repository root, once every block of t99's training split is made (scripts/slot_blocks.sh):
#   mkdir -p out/runs
#   nohup scripts/tshirt_cycle.sh 4 out/runs/tshirt-c9  >> out/runs/tshirt-c9.log 2>&1 &
#   nohup scripts/tshirt_cycle.sh 5 out/runs/tshirt-c9b >> out/runs/tshirt-c9b.log 2>&1 &
# then judge both with scripts/judge_tshirt_cycle.sh. Sessions 45-51 ran it to its end: the
# mean of the two runs' epoch 126 is the T-shirt shipped since session 51 (test 1.495 cm).
# To repeat the cycle, put its start in DIR first: `git show
# 78e9d22:models/tshirt-local.garnet > DIR/last.garnet` (the shipped file now records 126).
set -e
if [ $# -ne 2 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
SEED=$1 DIR=$2
mkdir -p "$DIR"
[ -f "$DIR/last.garnet" ] || [ -f "$DIR/mid-epoch.garnet" ] || cp models/tshirt-local.garnet "$DIR/last.garnet"
RAYON_NUM_THREADS=1 exec ./target/release/garnet train --data out/standard-x9-t99-lbs \
  --garment tshirt --variant local --batch 1 --grad-clip 200 --out "$DIR" --resume \
  --keep-epochs --epochs 126 --lr 5.5e-6 --cosine-to 1e-6 --seed "$SEED"
