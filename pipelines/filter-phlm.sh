#!/usr/bin/env bash
# Reproduces seed 003's Table 2 and Figures 3-4 (Iglesias-Guitian et al. 2016, "Pixel History Linear Models")
# on the built-in scenes: each scene is rendered by render-gbuffer with 1 sample per pixel and random sub-pixel
# jitter (the flickering "Non-AA" input) and with a 16-spp reference, every method of filter-phlm filters the
# input, and compare reports PSNR per frame (the paper's Figures 3-4, as PNG charts), average PSNR (Table 2) and
# the motion-compensated flicker measure, against the same reference, for the unfiltered input too.
#
# Usage: pipelines/filter-phlm.sh [BUILD_DIR] [OUT_DIR] [SCENE.glb ...]
#   BUILD_DIR  where the tools were built (default build/release)
#   OUT_DIR    report folder (default report/filter-phlm)
#   SCENE      scenes to run (default: the built-in fence, tower, fan and walkers scenes of assets/scenes)
# Environment: SIZE (default 512x288), FRAMES (default 0-47), FPS (default 40), METHODS (default
#   "phlm taa ema fxaa"), RENDER_ARGS (extra render-gbuffer options; default "--payload direct,shadow,ssao":
#   the gi payload's 2000 VPLs make the 16-spp reference ~10x slower on llvmpipe), FILTER_ARGS (extra
#   filter-phlm options), REUSE_RENDER=1 (keep an existing OUT_DIR/SCENE/render folder instead of rendering
#   again, e.g. after changing only the filters).
#
# The comparison target: render-gbuffer's `color` is the shading payload's R,G,B at one sample per pixel with
# the chosen jitter, and its `reference` is the same payload's R,G,B averaged over --reference-spp samples at
# Halton (2,3) positions (apps/render-gbuffer, libtemporal/src/render/renderer.cpp), so reference.####.exr's
# bare R,G,B is the 16-spp version of the colour input and is compared against directly.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${1:-build/release}"
OUT="${2:-report/filter-phlm}"
shift $(( $# > 2 ? 2 : $# ))
SIZE="${SIZE:-512x288}"
FRAMES="${FRAMES:-0-47}"
FPS="${FPS:-40}"
METHODS="${METHODS:-phlm taa ema fxaa}"
RENDER_ARGS="${RENDER_ARGS:---payload direct,shadow,ssao}"
REUSE_RENDER="${REUSE_RENDER:-0}"
FILTER_ARGS="${FILTER_ARGS:-}"

# A relative BUILD_DIR is taken from the current folder, else from the repository root.
case "$BUILD" in
  /*) ;;
  *) if [[ -d "$PWD/$BUILD" ]]; then BUILD="$PWD/$BUILD"; else BUILD="$here/$BUILD"; fi ;;
esac
render="$BUILD/apps/render-gbuffer/render-gbuffer"
filter="$BUILD/apps/filter-phlm/filter-phlm"
compare="$BUILD/apps/compare/compare"
for t in "$render" "$filter" "$compare"; do
  if [[ ! -x "$t" ]]; then
    echo "filter-phlm.sh: $t is missing: build the project first (cmake --preset release && cmake --build --preset release)" >&2
    exit 2
  fi
done

scenes=("$@")
if [[ ${#scenes[@]} -eq 0 ]]; then
  for s in fence tower fan walkers; do
    [[ -f "$here/assets/scenes/$s.glb" ]] && scenes+=("$here/assets/scenes/$s.glb")
  done
fi
if [[ ${#scenes[@]} -eq 0 ]]; then
  echo "filter-phlm.sh: no scenes given and none in $here/assets/scenes" >&2
  exit 2
fi

mkdir -p "$OUT"
summary="$OUT/summary.md"
{
  echo "# filter-phlm: seed 003 Table 2 on the built-in scenes"
  echo
  echo "Input: render-gbuffer colour, 1 spp, random jitter; reference: 16 spp. Size $SIZE, frames $FRAMES at $FPS fps."
  echo "Columns from compare: mean PSNR (RGB, dB), mean flicker (motion-compensated), mean compute ms per frame."
  echo
} > "$summary"

for scene in "${scenes[@]}"; do
  name="$(basename "${scene%.*}")"
  dir="$OUT/$name"
  mkdir -p "$dir"
  if [[ "$REUSE_RENDER" == 1 && -d "$dir/render" ]]; then
    echo "== $name: reusing $dir/render" >&2
  else
    echo "== $name: rendering ($SIZE, frames $FRAMES)" >&2
    # shellcheck disable=SC2086
    "$render" "$scene" --out "$dir/render" --size "$SIZE" --fps "$FPS" --frames "$FRAMES" \
      --outputs gbuffer,color,reference --jitter random --reference-spp 16 $RENDER_ARGS
  fi

  tests=("$dir/render/color.####.exr")
  names="input"
  for m in $METHODS; do
    echo "== $name: filter-phlm --method $m" >&2
    # shellcheck disable=SC2086
    "$filter" --input "$dir/render/color.####.exr" --gbuffer "$dir/render/gbuffer.####.exr" \
      --out "$dir/$m/$m.####.exr" --method "$m" $FILTER_ARGS
    tests+=("$dir/$m/$m.####.exr")
    names+=",$m"
  done

  echo "== $name: compare" >&2
  "$compare" --reference "$dir/render/reference.####.exr" "${tests[@]}" --names "$names" \
    --gbuffer "$dir/render/gbuffer.####.exr" --csv "$dir/metrics.csv" --json "$dir/metrics.json" \
    --plot "$dir/psnr.png" | tee "$dir/table.txt"

  {
    echo "## $name"
    echo
    echo '```'
    cat "$dir/table.txt"
    echo '```'
    echo
  } >> "$summary"
done

# Mean over the scenes of each sequence's mean PSNR (RGB) and flicker (the columns of compare's table).
{
  echo "## Mean over the scenes"
  echo
  echo '```'
  for s in "${scenes[@]}"; do
    cat "$OUT/$(basename "${s%.*}")/table.txt"
  done | awk '$1 != "sequence" && NF >= 6 {
      n[$1]++; p[$1] += $3; f[$1] += $6; if (!($1 in seen)) { seen[$1] = 1; order[++k] = $1 } }
    END {
      printf "%-12s %7s %10s %11s\n", "sequence", "scenes", "psnr_rgb", "flicker"
      for (i = 1; i <= k; i++) { s = order[i]; printf "%-12s %7d %10.3f %11.5f\n", s, n[s], p[s] / n[s], f[s] / n[s] }
    }'
  echo '```'
} >> "$summary"

echo
cat "$summary"
echo "filter-phlm.sh: report in $OUT (summary.md, per scene: metrics.csv, metrics.json, psnr*.png)" >&2
