#!/usr/bin/env bash
# Generates the thin-walled check clouds: eleven closed thin-walled shapes the corpus does
# not have (shapes.py), 5,000 and 1,000 noise-free points each, with fixed seeds.
# Usage: make.sh OUTDIR   (the meshes go to OUTDIR/meshes; under a minute)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); out=${1:?usage: make.sh OUTDIR}
S="/usr/bin/python3 $here/../tools/sample.py"
/usr/bin/python3 "$here/shapes.py" "$out/meshes"
sample_pair() {  # NAME SEED: the 5k cloud with SEED, the 1k one with SEED+1
  $S "$out/meshes/$1.off" "$out/${1}_sparse5k.ply" --n 5000 --seed "$2" >/dev/null
  $S "$out/meshes/$1.off" "$out/${1}_sparse1k.ply" --n 1000 --seed $(($2 + 1)) >/dev/null
}
seed=7001
for m in hollow_box hollow_ellipsoid pipe_thick pipe_long ring plate_square plate_thick; do
  sample_pair $m $seed; seed=$((seed + 2))
done
seed=9101
for m in hollow_torus lampshade flanged_ring washer; do
  sample_pair $m $seed; seed=$((seed + 2))
done
echo "thinwall: $(ls "$out"/*_meta.json | wc -l) clouds in $out"
