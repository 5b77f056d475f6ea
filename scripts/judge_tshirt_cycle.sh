#!/bin/bash
# Judges the two runs of scripts/tshirt_cycle.sh on t99's 900 validation T-shirts before
# anything touches the test split: each run's epochs 125 and 126, the mean of the two
# epoch-126 networks, that mean with the network shipped in session 50, and that network
# itself (the mean of both runs' epoch 125 and their start: 1.5416 there, 1.5011 on the test
# split; `git show db402a7:models/tshirt-local.garnet > out/hist/c9-ab125-ship.garnet` where
# session 50's file is gone). Session 51 ran it: the mean of the two epoch-126 networks,
# 1.5368 on validation and 1.4954 on test, was shipped. Writes out/hist/c9-ab126.garnet,
# out/hist/c9-ab126-ship.garnet and one `garnet eval` folder per candidate under
# out/eval-c9; prints each candidate's validation E_dist to four places. From the repository root:
#   scripts/judge_tshirt_cycle.sh out/runs/tshirt-c9 out/runs/tshirt-c9b
set -e
if [ $# -ne 2 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
A=$1 B=$2
G=./target/release/garnet
mkdir -p out/hist out/eval-c9
$G average --models "$A/epoch-126.garnet" "$B/epoch-126.garnet" --out out/hist/c9-ab126.garnet
$G average --models "$A/epoch-126.garnet" "$B/epoch-126.garnet" out/hist/c9-ab125-ship.garnet \
  --out out/hist/c9-ab126-ship.garnet
declare -A CANDIDATES=(
  [a125]="$A/epoch-125.garnet" [a126]="$A/epoch-126.garnet"
  [b125]="$B/epoch-125.garnet" [b126]="$B/epoch-126.garnet"
  [ab126]=out/hist/c9-ab126.garnet [ab126-ship]=out/hist/c9-ab126-ship.garnet
  [shipped]=out/hist/c9-ab125-ship.garnet
)
for name in "${!CANDIDATES[@]}"; do
  $G eval --data out/standard-x9-t99-lbs --split val --model "${CANDIDATES[$name]}" \
    --out "out/eval-c9/$name" > "out/eval-c9/$name.log" 2>&1
  python3 -c "import json, sys
r = json.load(open(sys.argv[2]))['table1'][0]
print(f\"{sys.argv[1]}: E_dist {r['e_dist_cm']:.4f} cm, E_norm {r['e_norm_deg']:.2f} deg\")" \
    "$name" "out/eval-c9/$name/results.json"
done
