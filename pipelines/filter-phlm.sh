#!/usr/bin/env bash
# Reproduces seed 003's Table 2 and Figures 3-4 (Iglesias-Guitian et al. 2016, "Pixel History Linear Models")
# on the built-in scenes: each scene is rendered by render-gbuffer with 1 sample per pixel and random sub-pixel
# jitter (the flickering "Non-AA" input) and with a 16-spp reference, every method of filter-phlm filters the
# input, and compare reports PSNR per frame (the paper's Figures 3-4, as PNG charts), average PSNR (Table 2) with
# its 95% interval and steady-state mean, the motion-compensated flicker measure, and paired differences between
# the methods, against the same reference, for the unfiltered input too.
#
# Usage: pipelines/filter-phlm.sh [BUILD_DIR] [OUT_DIR] [SCENE.glb ...]
#   BUILD_DIR  where the tools were built (default build/release)
#   OUT_DIR    report folder (default report/filter-phlm)
#   SCENE      scenes to run (default: the built-in fence, tower, fan and walkers scenes of assets/scenes)
# Environment: SIZE (default 512x288), FRAMES (default 0-47), FPS (default 40), METHODS (default: every method
#   of filter-phlm's registry, as `filter-phlm --list-methods` prints them; a named variant's name works too),
#   VARIANTS (more runs, one per line "NAME METHOD filter-phlm options", e.g. the previous TAA
#   "taa-0.1 taa --taa-alpha 0.1" (the engine-typical blend), "taa-2014 taa --taa-velocity centre --taa-clip
#   minmax --taa-alpha 0.04" and "ema-tuned-static ema --ema-alpha 0.9" by default; "" for none; the tuned
#   baselines, issue 24: on the tuning set (pipelines/filter-phlm-tune.sh at 256x144, 2026-11-26) TAA's optimum is
#   alpha 0.6 (the `taa` default) over the whole frame and on moving pixels and alpha 0.1 (`taa-0.1`) on static
#   pixels; EMA's is 0.5 (the `ema` default) over the whole frame and on moving pixels and 0.9 on static ones), TUNED (a file of more VARIANTS lines, e.g. the per-region
#   optimum of the baselines that pipelines/filter-phlm-tune.sh writes to OUT_DIR/tuned-variants.txt),
#   RENDER_ARGS (extra render-gbuffer options; default "--payload direct,shadow,ssao": the gi payload's 2000 VPLs
#   make the 16-spp reference ~10x slower on llvmpipe), FILTER_ARGS (extra filter-phlm options for every run),
#   REFERENCE_SPP (samples per pixel of the reference, default 16),
#   RENDERS (folder holding SCENE/render, default OUT_DIR: the ablation script reuses the Table 2 renders),
#   REUSE_RENDER=1 (keep an existing render folder instead of rendering again, e.g. after changing only the
#   filters), REUSE_OUTPUTS=1 (keep existing filtered sequences: measure again only), WARMUP (frames compare
#   reports apart as warm-up, default 10 = 1 / TAA's alpha; only when compare has --warmup), PAIRS (paired differences printed, "A:B,..."; default: phlm and taa against each other, the input
#   and the previous TAA), REGIONS (compare --regions: motion (default) or none), STATIC_FRAMES (compare
#   --static-frames, default 10), NOISE_FLOOR_FRAMES (default 3; 0: none): the first N frames of the reference are
#   also rendered at 4x REFERENCE_SPP and compare scores the reference against them: the reference's noise floor
#   (PSNR(reference, 4x reference)), printed above each scene's table; a best score within 10 dB of it is flagged.
#
# The comparison target: render-gbuffer's `color` is the shading payload's R,G,B at one sample per pixel with
# the chosen jitter, and its `reference` is the same payload's R,G,B averaged over --reference-spp samples at
# Halton (2,3) positions (apps/render-gbuffer, libtemporal/src/render/renderer.cpp), so reference.####.exr's
# bare R,G,B is the 16-spp version of the colour input and is compared against directly.
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

use_build "${1:-}"
OUT="${2:-report/filter-phlm}"
shift $(( $# > 2 ? 2 : $# ))
SIZE="${SIZE:-512x288}"
FRAMES="${FRAMES:-0-47}"
FPS="${FPS:-40}"
RENDER_ARGS="${RENDER_ARGS:---payload direct,shadow,ssao}"
REFERENCE_SPP="${REFERENCE_SPP:-16}"
REUSE_RENDER="${REUSE_RENDER:-0}"
REUSE_OUTPUTS="${REUSE_OUTPUTS:-0}"
FILTER_ARGS="${FILTER_ARGS:-}"
VARIANTS="${VARIANTS-taa-0.1 taa --taa-alpha 0.1
taa-2014 taa --taa-velocity centre --taa-clip minmax --taa-alpha 0.04
ema-tuned-static ema --ema-alpha 0.9}"
RENDERS="${RENDERS:-$OUT}"
WARMUP="${WARMUP:-10}"
REGIONS="${REGIONS:-motion}"
NOISE_FLOOR_FRAMES="${NOISE_FLOOR_FRAMES:-3}"
STATIC_FRAMES="${STATIC_FRAMES:-10}"
PAIRS="${PAIRS:-phlm:taa,phlm:taa-0.1,phlm:input,taa:input,taa:taa-0.1,phlm:fxaa,phlm:ema,phlm:ema-tuned-static,taa-0.1:taa-2014}"

require_tools render-gbuffer filter-phlm compare
filter="$(tool_path filter-phlm)"
compare="$(tool_path compare)"
METHODS="${METHODS:-$(methods_of filter-phlm)}"

use_scenes "fence tower fan walkers" "$@"

mkdir -p "$OUT"
summary="$OUT/summary.md"
# Every run: "NAME ARGUMENTS" (the METHODS through the registry under their own names first, then the variants).
runs=()
add_runs filter-phlm runs
if [[ -n "${TUNED:-}" ]]; then
  [[ -f "$TUNED" ]] || die "TUNED=$TUNED: no such file (pipelines/filter-phlm-tune.sh writes OUT_DIR/tuned-variants.txt)"
  add_variant_runs runs < "$TUNED"
fi
compare_args=()
compare_help="$("$compare" --help 2>/dev/null || true)"
if [[ "$compare_help" == *--warmup* ]]; then compare_args+=(--warmup "$WARMUP"); fi
# Every metric also per region (static / moving / disoccluded, from the G-buffer; docs/compare.md "Regions"): the
# tables show where a method wins and where it loses, not only the whole-frame mean.
if [[ "$REGIONS" != none && "$compare_help" == *--regions* ]]; then
  compare_args+=(--regions "$REGIONS" --static-frames "$STATIC_FRAMES")
fi
{
  echo "# filter-phlm: seed 003 Table 2 on the built-in scenes"
  echo
  echo "Input: render-gbuffer colour, 1 spp, random jitter; reference: 16 spp. Size $SIZE, frames $FRAMES at $FPS fps."
  echo "Columns from compare: mean PSNR (RGB, dB), mean flicker (motion-compensated), mean compute ms per frame."
  echo
  # Which baseline each column is (issue 24: the tables show the tuned baselines the text compares against): the
  # filter-phlm arguments of every run; a method's own name runs its defaults (the whole-frame tuned values).
  echo "Runs (filter-phlm arguments; defaults: docs/filter-phlm.md):"
  for run in "${runs[@]}"; do read -r n args <<< "$run"; echo "- \`$n\`: \`$args\`"; done
  echo
} > "$summary"

seq_names="input"
for run in "${runs[@]}"; do read -r n _ <<< "$run"; seq_names+=",$n"; done
scene_names=""
for scene in "${scenes[@]}"; do
  name="$(basename "${scene%.*}")"
  scene_names+="${scene_names:+,}$name"
  dir="$OUT/$name"
  render_dir="$RENDERS/$name/render"
  mkdir -p "$dir"
  # shellcheck disable=SC2086
  render_or_reuse "$name" "$render_dir" "($SIZE, frames $FRAMES)" "$scene" --size "$SIZE" --fps "$FPS" \
    --frames "$FRAMES" --outputs gbuffer,color,reference --jitter random --reference-spp "$REFERENCE_SPP" $RENDER_ARGS

  tests=("$render_dir/color.####.exr")
  last_frame="$(ls "$render_dir"/color.*.exr | tail -1)"
  last_frame="${last_frame##*/color.}"
  for run in "${runs[@]}"; do
    read -r n args <<< "$run"
    tests+=("$dir/$n/$n.####.exr")
    if [[ "$REUSE_OUTPUTS" == 1 && -f "$dir/$n/$n.$last_frame" ]]; then
      echo "== $name: reusing $dir/$n" >&2
      continue
    fi
    echo "== $name: $n = filter-phlm $args" >&2
    # shellcheck disable=SC2086
    "$filter" --input "$render_dir/color.####.exr" --gbuffer "$render_dir/gbuffer.####.exr" \
      --out "$dir/$n/$n.####.exr" $args $FILTER_ARGS
  done

  # The reference's noise floor: its first NOISE_FLOOR_FRAMES frames at 4x the samples, scored by compare
  # (lib.sh noise_floor_render / noise_floor_score, shared with upsample-st.sh and morph-120hz.sh).
  floor_json=""
  if [[ "$NOISE_FLOOR_FRAMES" -gt 0 ]]; then
    floor_range="$(floor_frames "$FRAMES" "$NOISE_FLOOR_FRAMES")"
    floor_dir="$RENDERS/$name/render-4x"
    # shellcheck disable=SC2086
    noise_floor_render "$scene" "$floor_dir" "$floor_range" $(( 4 * REFERENCE_SPP )) --size "$SIZE" --fps "$FPS" \
      --jitter random $RENDER_ARGS
    noise_floor_score "$render_dir/reference.####.exr" "$floor_dir/reference.####.exr" "$floor_range" \
      "$dir/noise-floor.json"
    floor_json="$dir/noise-floor.json"
  fi

  echo "== $name: compare" >&2
  "$compare" --reference "$render_dir/reference.####.exr" "${tests[@]}" --names "$seq_names" \
    --gbuffer "$render_dir/gbuffer.####.exr" --csv "$dir/metrics.csv" --json "$dir/metrics.json" \
    --plot "$dir/psnr.png" "${compare_args[@]}" | tee "$dir/table.txt"

  {
    echo "## $name"
    echo
    if [[ -n "$floor_json" ]]; then
      python3 "$TABLES" noise-floor "$floor_json" "$dir/metrics.json" "$REFERENCE_SPP" "$(( 4 * REFERENCE_SPP ))"
      echo
    fi
    code_block "$dir/table.txt"
  } >> "$summary"
done

{
  echo "## Table 2: mean PSNR (RGB, dB) [95% interval] (steady state) / mean flicker"
  echo
  python3 "$TABLES" scenes "$OUT" "$scene_names" "$seq_names" "$PAIRS"
  echo
} >> "$summary"

echo
cat "$summary"
say "report in $OUT (summary.md, per scene: metrics.csv, metrics.json, psnr*.png)"
