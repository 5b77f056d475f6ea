#!/bin/bash
# Makes dataset shards on a lent machine's many cores (the device tool's `run`), packed to
# come back in 15 MB pieces. It runs in the repository root there, with `.dev` carried:
#   .dev/garnet.xz                      the release binary built here (xz -c target/release/garnet)
#   .dev/home/body-v1.safetensors.xz    the body file from $GARNET_HOME, xz-compressed
#   .dev/mocap/...                      the clips the spec names, at their paths under the mocap root
#   .dev/shards.txt                     the --shard selection (a list may be longer than a command)
# Usage there: GEN_S=400 bash scripts/lent_machine_generate.sh specs/SPEC.toml
# Here: cat PIECES | xz -dc | tar x   into the dataset folder (its shards/ and parts/), then
# run the same generate command here; it takes the shard files in and makes what is left.
# The machine keeps /root/g between calls while it is warm: a second call resumes there.
set -x
SPEC=${1:?spec file}
G=/root/g; mkdir -p $G/home
xz -dc .dev/garnet.xz > $G/garnet && chmod +x $G/garnet
export GARNET_HOME=$G/home
xz -dc .dev/home/body-v1.safetensors.xz > $GARNET_HOME/body-v1.safetensors
nproc; date
touch $G/start
timeout ${GEN_S:-400} $G/garnet dataset generate $SPEC --out $G/d --jobs $(nproc) \
  --shard $(cat .dev/shards.txt) --mocap .dev/mocap > $G/gen.log 2>&1
date; tail -c 300 $G/gen.log
cd $G/d && find shards parts -type f -newer $G/start > $G/new.list; wc -l < $G/new.list
tar cf - -T $G/new.list | xz -T0 -6 > $G/pack.tar.xz && rm -f $G/pk.* && ls -la $G/pack.tar.xz
cd $G && split -b 15M -d -a 2 pack.tar.xz pk. && cp pk.* $OUT/ && sha256sum pk.* > $OUT/pk.sha
