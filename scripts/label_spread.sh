#!/bin/bash
# How far apart equally valid labels are, and how much of a network's error that is
# (docs/training-log.md "How far apart equally valid labels are (session 52)"). Makes DATASET's
# test split again twice, with the cloth 0.1% heavier (set a) and 0.1% lighter (set b), a
# physically empty change; evaluates each MODEL on the three sets with --save-drapes; and
# prints `scripts/drape_errors.py noise` for each. Resumable: what is made is kept in OUT.
# Runs ./target/release/garnet; usage, from the repository root:
#   scripts/label_spread.sh OUT DATASET MODEL...
# Session 52's run (each set about 400 s on 2 cores):
#   scripts/label_spread.sh out/noise out/standard-lbs models/tshirt-local.garnet \
#     models/sweater-local.garnet models/jeans-local.garnet
set -e
if [ $# -lt 3 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
OUT=$1 DATA=$2
shift 2
mkdir -p "$OUT"
for set in a:1.001 b:0.999; do
  name=${set%%:*} scale=${set##*:}
  # A set already begun goes on with the spec it was begun with (session 52's were made
  # from copies written another way, and a dataset refuses a spec that hashes otherwise).
  if [ -f "$OUT/$name/spec.toml" ]; then
    cp "$OUT/$name/spec.toml" "$OUT/$name.toml"
  else
    # The spec with its cloth density scaled (0.15 kg/m^2 when the spec leaves it out).
    python3 - "$DATA/spec.toml" "$scale" "$name" > "$OUT/$name.toml" <<'PY'
import re, sys, tomllib
text = open(sys.argv[1]).read()
density = round(tomllib.loads(text).get('simulator', {}).get('density', 0.15) * float(sys.argv[2]), 9)
text = re.sub(r'(?m)^name = "(.*)"', lambda m: f'name = "{m.group(1)}-{sys.argv[3]}"', text, 1)
text = re.sub(r'(?m)^density = .*\n', '', text)
if not re.search(r'(?m)^\[simulator\]', text):
    text += '\n[simulator]\n'
print(re.sub(r'(?m)^\[simulator\]\n', f'[simulator]\ndensity = {density!r}\n', text, 1), end='')
PY
  fi
  ./target/release/garnet dataset generate "$OUT/$name.toml" --out "$OUT/$name" --split test
done
for model in "$@"; do
  tag=$(basename "$model" .garnet)
  for set in 0 a b; do
    data=$OUT/$set; [ $set = 0 ] && data=$DATA
    drapes=$OUT/drapes-$tag-$set
    [ -f "$drapes-eval/results.json" ] || ./target/release/garnet eval --data "$data" --split test --model "$model" \
      --save-drapes "$drapes" --out "$drapes-eval" > "$drapes.log" 2>&1 \
      || { cat "$drapes.log" >&2; exit 1; }
  done
  echo "== $model"
  python3 scripts/drape_errors.py noise "$DATA" "$OUT/drapes-$tag-0" "$OUT/drapes-$tag-a" \
    "$OUT/drapes-$tag-b"
done
