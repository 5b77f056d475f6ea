#!/bin/bash
# Judges two runs of scripts/cycle.sh on DATA's validation split before anything touches a
# test split: for each EPOCH given, each run's network, the mean of the two (`garnet
# average`) and that mean with START (the network the cycle started from; left out when
# START was trained with other loss settings, which `garnet average` refuses), and START
# itself. Writes the means to out/hist/NAME-abEPOCH.garnet and NAME-abEPOCH-start.garnet,
# one `garnet eval` folder per candidate under out/eval-NAME, and prints each candidate's
# validation E_dist to four places. From the repository root:
#   scripts/judge_cycle.sh NAME DATA START RUN_A RUN_B EPOCH...
# The T-shirt's cycle of sessions 45-51 (START: session 50's network, `git show
# db402a7:models/tshirt-local.garnet`; its epoch-126 mean was shipped):
#   scripts/judge_cycle.sh c9 out/standard-x9-t99-lbs START out/runs/tshirt-c9 \
#     out/runs/tshirt-c9b 126
set -e
if [ $# -lt 6 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
NAME=$1 DATA=$2 START=$3 A=$4 B=$5
shift 5
G=./target/release/garnet
mkdir -p out/hist "out/eval-$NAME"
judge() {
  $G eval --data "$DATA" --split val --model "$2" --out "out/eval-$NAME/$1" \
    > "out/eval-$NAME/$1.log" 2>&1
  python3 -c "import json, sys
r = json.load(open(sys.argv[2]))['table1'][0]
print(f\"{sys.argv[1]}: E_dist {r['e_dist_cm']:.4f} cm, E_norm {r['e_norm_deg']:.2f} deg\")" \
    "$1" "out/eval-$NAME/$1/results.json"
}
judge start "$START"
for E in "$@"; do
  MEAN=out/hist/$NAME-ab$E.garnet
  $G average --models "$A/epoch-$E.garnet" "$B/epoch-$E.garnet" --out "$MEAN"
  judge "a$E" "$A/epoch-$E.garnet"
  judge "b$E" "$B/epoch-$E.garnet"
  judge "ab$E" "$MEAN"
  # A START trained with other loss settings (the cycle switched them) is not averaged.
  if $G average --models "$A/epoch-$E.garnet" "$B/epoch-$E.garnet" "$START" \
    --out "out/hist/$NAME-ab$E-start.garnet"; then
    judge "ab$E-start" "out/hist/$NAME-ab$E-start.garnet"
  fi
done
