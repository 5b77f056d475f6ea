#!/bin/bash
# Makes the T-shirts of standard-x9-t99-lbs's training bodies one slot block at a time:
# block k (0-10) is shard 11b + k of every training body b, nine poses each (blocks 0-8 are
# the slots 0-80 of standard-x9-t81-lbs, 9-10 the fresh slots 81-98), so whatever is done
# when a session ends is balanced over the bodies. Resumable: rerun it and `dataset
# generate` skips what is made. Usage, from the repository root:
#   nohup scripts/t99_blocks.sh [JOBS] [BLOCK...] > out/t99-blocks.log 2>&1 &
# (default: 2 jobs, blocks 0 to 8). Needs out/standard-x9-t99-lbs started (its manifest,
# for the split) or out/standard-x9-t90-lbs; see docs/model.md "Remaking t81 into t99".
set -e
JOBS=${1:-2}
shift || true
BLOCKS=${*:-0 1 2 3 4 5 6 7 8}
OUT=out/standard-x9-t99-lbs
MANIFEST=$OUT/manifest.json
[ -f $MANIFEST ] || MANIFEST=out/standard-x9-t90-lbs/manifest.json
for k in $BLOCKS; do
  SHARDS=$(python3 -c "import json; m = json.load(open('$MANIFEST')); \
print(','.join(str(11 * b + $k) for b in sorted(m['splits']['train'])))")
  echo "block $k: $(date)"
  ./target/release/garnet dataset generate specs/standard-x9-t99-lbs.toml --out $OUT \
    --jobs $JOBS --shard $SHARDS
done
