#!/usr/bin/env bash
# Generates the held-out clouds: eleven closed meshes gmpu was never tuned on, from CGAL's
# sample data as Debian's libcgal-demo ships it (beside the bench's CGAL peer, libcgal-dev),
# sampled like the development corpus (tests/data/corpus/make.sh: clean, noise σ 0.5 % and
# 1 % of the diagonal, ten-fold nonuniform density, 5k and 1k points) with their own fixed
# seeds.
# Usage: make.sh OUTDIR   (the meshes go to OUTDIR/meshes; about two minutes)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd); out=${1:?usage: make.sh OUTDIR}
data=${CGAL_SAMPLE_DATA:-/usr/share/doc/libcgal-dev/data.tar.gz}
if [ ! -f "$data" ]; then
  echo "heldout: $data is missing: install Debian's libcgal-demo (make deps-bench)" >&2
  exit 1
fi
# armadillo and homer: organic; turbine (genus 11) and anchor_dense (genus 4): CAD parts;
# cheese: a block with 133 small holes (porous). Added later, after the same rule (closed, and
# never looked at while tuning): elk (thin antlers and legs, genus 1), bull and diplodocus
# (organic), dragknob, joint (genus 2) and part (low-polygon CAD parts: flat faces, sharp
# edges). Each model keeps its seeds when others are added after it.
models="armadillo homer turbine anchor_dense cheese elk bull diplodocus dragknob joint part"
mkdir -p "$out/meshes"
tar xzf "$data" -C "$out/meshes" --strip-components=2 $(for m in $models; do echo "data/meshes/$m.off"; done)
source "$here/../tools/variants.sh"
seed=5000
for m in $models; do
  sample_variants "$out/meshes/$m.off" "$out" "$m" $seed
  seed=$((seed+10))
done
echo "heldout: $(ls "$out"/*_meta.json | wc -l) clouds in $out"
