#!/usr/bin/env bash
# Issue 16 item 8: temporal filters scoring below their own 1-spp input on thin edges under camera motion, with a
# noise-free payload (direct light and shadow only: the only error of the 1-spp input is aliasing). Renders each
# case, runs phlm and taa with every history / model fetch (bilinear, Catmull-Rom, nearest), the previous TAA and
# ema, and measures with compare (PSNR, flicker) and phlm_edge_split (the error on edge pixels against surface
# interiors, and the sub-pixel shift that best aligns each output with the reference: 0 for blur, +-0.5 for a
# half-pixel convention mismatch).
#
# Cases (CASES, one per line "name scene render-options"; a scene path that does not exist is skipped with a note,
# so the shared assets are optional):
#   fence          assets/scenes/fence.glb, its own drifting camera
#   helmet-orbit   ../shared/assets/gltf/FlightHelmet/FlightHelmet.gltf, --camera-path orbit (straps, goggles,
#                  fine textures: the third-party case of issue 16 item 8)
#   helmet-static  the same scene, automatic camera standing still (--camera-path fixed): no motion, so no
#                  history resampling; only jitter and the reference convention remain
#   ivy-orbit      ../shared/assets/gltf/SponzaIvy/sponza_ivy.gltf, --camera-path orbit (thin foliage, small in
#                  the frame)
#
# Usage: pipelines/filter-phlm-edges.sh [BUILD_DIR=build/release] [OUT_DIR=report/filter-phlm-edges]
# Environment: SIZE (512x288), FRAMES (0-47), FPS (40), WARMUP (10), CASES, REUSE_RENDER=1, SHARED_ASSETS (the
#   third-party assets folder, default ../shared/assets beside the repository; a worktree sets it to its path).
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

use_build "${1:-}"
OUT="${2:-report/filter-phlm-edges}"
SIZE="${SIZE:-512x288}"
FRAMES="${FRAMES:-0-47}"
FPS="${FPS:-40}"
WARMUP="${WARMUP:-10}"
REUSE_RENDER="${REUSE_RENDER:-0}"
shared="${SHARED_ASSETS:-$ROOT/../shared/assets}/gltf"
CASES="${CASES:-fence $ROOT/assets/scenes/fence.glb
helmet-orbit $shared/FlightHelmet/FlightHelmet.gltf --camera-path orbit
helmet-static $shared/FlightHelmet/FlightHelmet.gltf --camera-path fixed
ivy-orbit $shared/SponzaIvy/sponza_ivy.gltf --camera-path orbit}"

require_tools render-gbuffer filter-phlm compare tests/benchmarks/phlm/phlm_edge_split
filter="$(tool_path filter-phlm)"
compare="$(tool_path compare)"
split="$(tool_path tests/benchmarks/phlm/phlm_edge_split)"

# The runs, "NAME METHOD options": this study's fetch and velocity variants (an experiment's choice, not a
# method list).
runs=("phlm phlm"
  "phlm-catmull-rom phlm --model-fetch catmull-rom"
  "phlm-nearest phlm --model-fetch nearest"
  "taa taa"
  "taa-bilinear taa --taa-history bilinear"
  "taa-centre taa --taa-velocity centre"
  "taa-2014 taa --taa-velocity centre --taa-clip minmax --taa-alpha 0.04"
  "ema ema")
mkdir -p "$OUT"
summary="$OUT/summary.md"
{
  echo "# filter-phlm: edges under camera motion (issue 16, item 8)"
  echo
  echo "Payload direct + shadow (noise-free), 1 spp random jitter, 16-spp reference; $SIZE, frames $FRAMES at $FPS fps;"
  echo "the first $WARMUP frames are left out of the edge split."
  echo
} > "$summary"

while read -r name scene opts; do
  [[ -z "$name" ]] && continue
  if [[ ! -f "$scene" ]]; then
    echo "== $name: $scene not found, skipped" >&2
    echo "$name: skipped ($scene not found)" >> "$summary"
    continue
  fi
  dir="$OUT/$name"
  r="$dir/render"
  # shellcheck disable=SC2086
  render_or_reuse "$name" "$r" "$scene $opts" "$scene" --size "$SIZE" --fps "$FPS" --frames "$FRAMES" \
    --outputs gbuffer,color,reference --jitter random --reference-spp 16 --payload direct,shadow $opts
  tests=("$r/color.####.exr")
  names="input"
  pairs=("input=$r/color.####.exr")
  for run in "${runs[@]}"; do
    read -r n m args <<< "$run"
    echo "== $name: $n" >&2
    # shellcheck disable=SC2086
    "$filter" --input "$r/color.####.exr" --gbuffer "$r/gbuffer.####.exr" --out "$dir/$n/$n.####.exr" --method "$m" $args
    tests+=("$dir/$n/$n.####.exr")
    names+=",$n"
    pairs+=("$n=$dir/$n/$n.####.exr")
  done
  "$compare" --reference "$r/reference.####.exr" "${tests[@]}" --names "$names" --gbuffer "$r/gbuffer.####.exr" \
    --csv "$dir/metrics.csv" --json "$dir/metrics.json" > "$dir/table.txt"
  "$split" --reference "$r/reference.####.exr" --gbuffer "$r/gbuffer.####.exr" --warmup "$WARMUP" "${pairs[@]}" \
    > "$dir/edges.md"
  {
    echo "## $name ($(basename "$scene") $opts)"
    echo
    cat "$dir/edges.md"
    echo
    code_block "$dir/table.txt"
  } >> "$summary"
done <<< "$CASES"
cat "$summary"
