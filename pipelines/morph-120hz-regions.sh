#!/usr/bin/env bash
# Where the in-between error of each morph-120hz method comes from (docs/morph-120hz.md, "Where didyk loses"):
# splits the squared error of every in-between frame t = 3n + k (k = 1, 2) against the native 120 Hz frame into
#   M  pixels that move at t (native motion at t non-zero: the walkers, the fan blades, a panning camera's view),
#   D  pixels static at t that moved in the rendered frame 3n the method extrapolates from (where a moving object
#      was: disocclusions, the trailing side of a silhouette),
#   S  pixels static at t and at 3n, split into
#      C  those whose native colour changed between 3n and t by more than 1e-3 (in any channel sum): moving
#         shadows and lighting on static surfaces, which carry no motion vectors, so the rendered frame 3n is
#         wrong there for every method that extrapolates from it,
#         of which L: the large changes (channel sum above 0.05: a shadow's edge passing), the rest being small
#         ones (the SSAO and VPL noise, which is drawn per instant, and slow shading changes),
#      U  the unchanged rest (the native frame 3n is exact there: any error is what a method smears into them),
# and reports per method the mean in-between PSNR, each region's share of the squared error, and the PSNR it
# would have with a region's error removed (10 log10(1 / (MSE - the region's part)), averaged over frames as
# the table's PSNR is).
#
# Usage: [METHODS="didyk repeat ..."] pipelines/morph-120hz-regions.sh SCENE_DIR [BUILD_DIR]
#   SCENE_DIR  one scene's folder of pipelines/morph-120hz.sh (r120/, ldr120/, one folder per method)
#   BUILD_DIR  default build/release (compare; morph-120hz for the default METHODS)
#   METHODS    method folders of SCENE_DIR to split (default: every method of morph-120hz's registry and
#              minterpolate, those present; any other folder of output frames color.####.exr works, e.g. an
#              ablation of didyk)
# Writes SCENE_DIR/regions.csv and prints it.
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
D=${1:?usage: morph-120hz-regions.sh SCENE_DIR [BUILD_DIR]}
use_build "${2:-}"
require_tools compare
COMPARE="$(tool_path compare)"
FACTOR=3
command -v oiiotool >/dev/null 2>&1 || die "oiiotool not found"
if [[ -z "${METHODS:-}" ]]; then
  require_tools morph-120hz
  METHODS="$(methods_of morph-120hz) minterpolate"
fi
methods=()
for m in $METHODS; do [[ -d "$D/$m" ]] && methods+=("$m"); done
(( ${#methods[@]} )) || die "no method folder in $D"
last=$(ls "${D}/${methods[0]}"/color.*.exr | wc -l); last=$((last - 1))

# moving(f): 1 where |motion.X| + |motion.Y| of the native 120 Hz frame f exceeds 1e-3 px, else 0.
mkdir -p "$D/regions/moving" "$D/regions/ref"
for ((f = 0; f <= last; ++f)); do
  printf -v n "%04d" "$f"
  oiiotool "$D/r120/gbuffer.$n.exr" --subimage motion --ch motion.X,motion.Y --abs --chsum --mulc 1000 \
    --clamp:min=0:max=1 -d float -o "$D/regions/moving/m.$n.exr"
done
# The reference with three masks: regionM (moving at t), regionS (static at t and at the rendered frame 3n) and
# regionC (static at both, colour changed between them).
for ((f = FACTOR; f <= last; ++f)); do
  printf -v n "%04d" "$f"
  printf -v s "%04d" $((f / FACTOR * FACTOR))
  oiiotool "$D/regions/moving/m.$n.exr" --chnames regionM \
    "$D/regions/moving/m.$n.exr" --subc 1 --abs "$D/regions/moving/m.$s.exr" --subc 1 --abs --mul --chnames regionS \
    --chappend \
    "$D/regions/moving/m.$n.exr" --subc 1 --abs "$D/regions/moving/m.$s.exr" --subc 1 --abs --mul \
    "$D/ldr120/color.$n.exr" --ch R,G,B "$D/ldr120/color.$s.exr" --ch R,G,B --absdiff --chsum --mulc 1000 \
    --clamp:min=0:max=1 --mul --chnames regionC --chappend \
    "$D/regions/moving/m.$n.exr" --subc 1 --abs "$D/regions/moving/m.$s.exr" --subc 1 --abs --mul \
    "$D/ldr120/color.$n.exr" --ch R,G,B "$D/ldr120/color.$s.exr" --ch R,G,B --absdiff --chsum --mulc 10 \
    --clamp:min=0:max=1 --mul --chnames regionL --chappend \
    "$D/ldr120/color.$n.exr" --ch R,G,B --swap --chappend -d float --compression zip \
    -o "$D/regions/ref/c.$n.exr"
done

tests=()
for m in "${methods[@]}"; do tests+=("$D/$m/color.####.exr"); done
IFS=, ; names="${methods[*]}"; unset IFS
for r in M S C L; do
  "$COMPARE" --reference "$D/regions/ref/c.####.exr" "${tests[@]}" --names "$names" --frames "$FACTOR-$last" \
    --mask "region$r" --csv "$D/regions/region$r.csv" > /dev/null
done

# Per method over the in-between frames: mean PSNR, mean share of each region in the MSE, and the PSNR with a
# region's error removed (tables.py regions: statistics compare does not compute over masked regions).
python3 "$TABLES" regions "$FACTOR" "$D/regions/regionM.csv" "$D/regions/regionS.csv" "$D/regions/regionC.csv" \
  "$D/regions/regionL.csv" "${methods[@]}" > "$D/regions.csv"
column -s, -t < "$D/regions.csv"
