#!/bin/bash
# Makes a dataset's drapes one slot block at a time, so that whatever is done when a session
# ends is balanced over the bodies: block k is shard BASE + STRIDE * b + k for every body b
# of SPLIT (each shard holding one block of a body's poses). Resumable: run it again and
# `dataset generate` skips what is made. The split's bodies come from OUT's manifest, which a
# new folder gets from `dataset generate --max-samples 0` before any drape is made. Runs
# ./target/release/garnet; usage, from the repository root:
#   nohup scripts/slot_blocks.sh SPEC OUT BASE STRIDE SPLIT JOBS BLOCK... > LOG 2>&1 &
# The T-shirts of standard-x9-t99-lbs's training bodies (t81's slots 0-80 are blocks 0-8,
# the fresh slots 81-98 blocks 9-10; docs/training-log.md "Remaking t81 into t99"):
#   scripts/slot_blocks.sh specs/standard-x9-t99-lbs.toml out/standard-x9-t99-lbs 0 11 \
#     train 2 0 1 2 3 4 5 6 7 8
# and its 900 validation T-shirts (slots 0-44 of the validation bodies):
#   scripts/slot_blocks.sh specs/standard-x9-t99-lbs.toml out/standard-x9-t99-lbs 0 11 \
#     val 2 0 1 2 3 4
# The sweaters of standard-x9-sw54-lbs (training blocks 0-5, then validation blocks 0-2):
#   scripts/slot_blocks.sh specs/standard-x9-sw54-lbs.toml out/standard-x9-sw54-lbs 2400 6 \
#     train 2 0 1 2 3 4 5
#   scripts/slot_blocks.sh specs/standard-x9-sw54-lbs.toml out/standard-x9-sw54-lbs 2400 6 \
#     val 2 0 1 2
set -e
if [ $# -lt 7 ]; then
  sed -n '2,/^[^#]/{/^#/p}' "$0" >&2
  exit 2
fi
SPEC=$1 OUT=$2 BASE=$3 STRIDE=$4 SPLIT=$5 JOBS=$6
shift 6
MANIFEST=$OUT/manifest.json
# A new folder gets its manifest (and with it the splits) before any drape is made.
[ -f "$MANIFEST" ] || ./target/release/garnet dataset generate "$SPEC" --out "$OUT" --max-samples 0
for k in "$@"; do
  SHARDS=$(python3 -c "import json, sys
m = json.load(open(sys.argv[1]))
base, stride, k = (int(a) for a in sys.argv[3:6])
print(','.join(str(base + stride * b + k) for b in sorted(m['splits'][sys.argv[2]])))" \
    "$MANIFEST" "$SPLIT" "$BASE" "$STRIDE" "$k")
  echo "$SPLIT block $k: $(date)"
  ./target/release/garnet dataset generate "$SPEC" --out "$OUT" --jobs "$JOBS" --shard "$SHARDS"
done
