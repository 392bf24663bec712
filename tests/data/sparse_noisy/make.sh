#!/usr/bin/env bash
# Generates the sparse noisy clouds: the development corpus's 17 closed meshes sampled the way
# a hand-held or long-range scan sees them, few points and noisy at once (1k points with noise
# σ 0.5 % and 1 % of the diagonal, 5k points with 1 %), with their own fixed seeds. The
# corpus has each condition alone, not both.
# Usage: make.sh OUTDIR   (under a minute)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); out=${1:?usage: make.sh OUTDIR}; mkdir -p "$out"
S="/usr/bin/python3 $here/../tools/sample.py"
meshes="$here/../corpus/meshes"
closed="bear camel cow dino femur hand helmet man pinion rotor couplingdown spool triceratops handle hollow_sphere thin_plate pipe"
seed=9000
for m in $closed; do
  M="$meshes/$m.off"
  $S "$M" "$out/${m}_sparse1k-noise0.5.ply" --n 1000 --noise 0.005 --seed $seed       >/dev/null
  $S "$M" "$out/${m}_sparse1k-noise1.0.ply" --n 1000 --noise 0.010 --seed $((seed+1)) >/dev/null
  $S "$M" "$out/${m}_sparse5k-noise1.0.ply" --n 5000 --noise 0.010 --seed $((seed+2)) >/dev/null
  seed=$((seed+10))
done
echo "sparse_noisy: $(ls "$out"/*_meta.json | wc -l) clouds in $out"
