# Sourced by the make.sh scripts of tests/data: the six variants of one closed mesh, sampled
# with seeds SEED..SEED+5 (clean, noise σ 0.5 % and 1 % of the diagonal, ten-fold nonuniform
# density along z, 5k and 1k points). Usage: sample_variants MESH OUTDIR NAME SEED
sample_variants() {
  local M=$1 out=$2 m=$3 seed=$4
  local S="/usr/bin/python3 $(dirname "${BASH_SOURCE[0]}")/sample.py"
  $S "$M" "$out/${m}_clean.ply"      --n 35000 --seed $seed                 >/dev/null
  $S "$M" "$out/${m}_noise0.5.ply"   --n 35000 --noise 0.005 --seed $((seed+1)) >/dev/null
  $S "$M" "$out/${m}_noise1.0.ply"   --n 35000 --noise 0.010 --seed $((seed+2)) >/dev/null
  $S "$M" "$out/${m}_nonuniform.ply" --n 35000 --nonuniform --axis 2 --seed $((seed+3)) >/dev/null
  $S "$M" "$out/${m}_sparse5k.ply"   --n 5000  --seed $((seed+4))           >/dev/null
  $S "$M" "$out/${m}_sparse1k.ply"   --n 1000  --seed $((seed+5))           >/dev/null
}
