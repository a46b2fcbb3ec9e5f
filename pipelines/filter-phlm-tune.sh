#!/usr/bin/env bash
# Chooses the free parameters of filter-phlm's baselines on a tuning set that no evaluation uses, and shows PHLM's
# own sweep beside them (PHLM keeps the paper's constants). Issue 16: "each baseline's free parameters chosen by a
# sweep script on the project's own scenes (never on an evaluation scene), with the curve published in docs and the
# chosen value stated".
#
# The tuning set (docs/filter-phlm.md, "Tuning the baselines"): sequences that render-gbuffer makes from
# assets/scenes with camera positions, animation times and a noise seed that the evaluation
# (pipelines/filter-phlm.sh: frames 0-47 of each scene's own camera, --seed 0) never uses:
#   tower-far         tower.glb frames 240-271 (t = 6.0-6.8 s: the far side of the 12 s fly-around)   --seed 101
#   fence-late        fence.glb frames 160-191 (t = 4.0-4.8 s: the other half of the 8 s drift)       --seed 102
#   walkers-late      walkers.glb frames 100-131 (t = 2.5-3.3 s; same static camera, the characters
#                     elsewhere on their circles: the closest to an evaluation sequence)                --seed 103
#   fan-dolly         fan.glb --camera-path dolly frames 100-131 (the automatic camera moving in and out)   --seed 104
#   morph_test-orbit  morph_test.glb --camera-path orbit frames 100-131 (not an evaluation scene)     --seed 105
# rendered like the evaluation (SIZE 512x288, 40 fps, 1 spp random jitter, 16-spp reference, payload
# direct,shadow,ssao).
#
# Sweeps (one filter-phlm run per value and tuning sequence; one compare per sequence):
#   taa   --taa-alpha in TAA_ALPHAS x --taa-clip variance|minmax (velocity nearest, Catmull-Rom history, gamma 1)
#   ema   --ema-alpha in EMA_ALPHAS
#   fxaa  --fxaa-subpix in FXAA_SUBPIX (Lottes' edge thresholds kept)
#   phlm  --lambda in PHLM_LAMBDAS (shown, not chosen: the paper's 0.998 stays)
# The criterion is the mean over the tuning sequences of compare's mean PSNR (RGB) per sequence (seed 003 Table 2's
# measure); flicker is tabulated beside it. Writes OUT_DIR/tuning.md (tables, the chosen values) and
# OUT_DIR/tuning.csv (every run: method, setting, sequence, psnr, flicker).
# Per region (issue 24): compare runs with --regions motion (static = no motion, no disocclusion and the reference
# unchanged over STATIC_FRAMES frames; moving; disoccluded; docs/compare.md "Regions"), and the same criterion per
# region - the mean over the tuning sequences that have pixels of the region of compare's mean PSNR in it - gives
# the static-region and moving-region optimum beside the whole-frame one: OUT_DIR/tuning-regions.csv (every run and
# region: method, setting, sequence, region, share, psnr, pooled psnr, flicker), a per-region section in
# tuning.md, and OUT_DIR/tuned-variants.txt, the static and moving optimum of taa and ema as filter-phlm.sh
# VARIANTS lines ("taa-tuned-static taa --taa-clip variance --taa-alpha 0.2"; filter-phlm.sh's TUNED=FILE).
#
# Usage: pipelines/filter-phlm-tune.sh [BUILD_DIR=build/release] [OUT_DIR=report/filter-phlm-tune]
# Environment: SIZE, FPS, TAA_ALPHAS, TAA_CLIPS (default "variance minmax"), EMA_ALPHAS, FXAA_SUBPIX, PHLM_LAMBDAS,
#   STATIC_FRAMES (compare --static-frames, default 10), TUNE_SET (lines
#   "name scene.glb frames render-options"), REUSE_RENDER=1 (keep existing renders), KEEP_OUTPUTS=1 (keep the
#   filtered sequences; by default they are deleted after compare has measured them), APPEND=1 (add the runs to an
#   existing OUT_DIR/tuning.csv, e.g. to extend a grid; the tables sort the settings). An empty list (TAA_ALPHAS="")
#   skips that method.
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

use_build "${1:-}"
OUT="${2:-report/filter-phlm-tune}"
SIZE="${SIZE:-512x288}"
FPS="${FPS:-40}"
TAA_ALPHAS="${TAA_ALPHAS-0.02 0.04 0.06 0.08 0.1 0.125 0.15 0.2 0.25 0.33 0.4 0.5 0.6 0.75 1}"
EMA_ALPHAS="${EMA_ALPHAS-0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.85 0.9 0.95}"
FXAA_SUBPIX="${FXAA_SUBPIX-0 0.25 0.5 0.75 1}"
PHLM_LAMBDAS="${PHLM_LAMBDAS-0.9 0.95 0.98 0.99 0.995 0.998 0.999}"
TAA_CLIPS="${TAA_CLIPS:-variance minmax}"
STATIC_FRAMES="${STATIC_FRAMES:-10}"
REUSE_RENDER="${REUSE_RENDER:-0}"
KEEP_OUTPUTS="${KEEP_OUTPUTS:-0}"
APPEND="${APPEND:-0}"
TUNE_SET="${TUNE_SET:-tower-far tower.glb 240-271 --seed 101
fence-late fence.glb 160-191 --seed 102
walkers-late walkers.glb 100-131 --seed 103
fan-dolly fan.glb 100-131 --camera-path dolly --seed 104
morph_test-orbit morph_test.glb 100-131 --camera-path orbit --seed 105}"

require_tools render-gbuffer filter-phlm compare
filter="$(tool_path filter-phlm)"
compare="$(tool_path compare)"
mkdir -p "$OUT"

# The runs: "method label filter-options" per line.
runs=()
for a in $TAA_ALPHAS; do
  for clip in $TAA_CLIPS; do runs+=("taa clip=$clip/alpha=$a --taa-clip $clip --taa-alpha $a"); done
done
for a in $EMA_ALPHAS; do runs+=("ema alpha=$a --ema-alpha $a"); done
for s in $FXAA_SUBPIX; do runs+=("fxaa subpix=$s --fxaa-subpix $s"); done
for l in $PHLM_LAMBDAS; do runs+=("phlm lambda=$l --lambda $l"); done

csv="$OUT/tuning.csv"
region_csv="$OUT/tuning-regions.csv"
if [[ "$APPEND" != 1 || ! -f "$csv" ]]; then echo "method,setting,sequence,psnr_rgb_db,flicker" > "$csv"; fi
if [[ "$APPEND" != 1 || ! -f "$region_csv" ]]; then
  echo "method,setting,sequence,region,share,psnr_rgb_db,psnr_rgb_pooled_db,flicker" > "$region_csv"
fi
region_args=()
if [[ "$("$compare" --help 2>/dev/null || true)" == *--regions* ]]; then
  region_args=(--regions motion --static-frames "$STATIC_FRAMES")
fi
while read -r name scene frames opts; do
  [[ -z "$name" ]] && continue
  dir="$OUT/$name"
  mkdir -p "$dir"
  # shellcheck disable=SC2086
  render_or_reuse "$name" "$dir/render" "$scene $opts ($SIZE, frames $frames)" "$ROOT/assets/scenes/$scene" \
    --size "$SIZE" --fps "$FPS" --frames "$frames" --outputs gbuffer,color,reference --jitter random \
    --reference-spp 16 --payload direct,shadow,ssao $opts
  tests=()
  names=""
  i=0
  rm -rf "$dir/runs"
  for run in "${runs[@]}"; do
    read -r method _ args <<< "$run"  # the setting label is for tuning.csv
    out="$dir/runs/$i/$method.####.exr"
    # shellcheck disable=SC2086
    "$filter" --input "$dir/render/color.####.exr" --gbuffer "$dir/render/gbuffer.####.exr" --out "$out" \
      --method "$method" $args
    tests+=("$out")
    names+="${names:+,}$i"
    i=$((i + 1))
  done
  echo "== $name: compare (${#tests[@]} runs)" >&2
  "$compare" --reference "$dir/render/reference.####.exr" "${tests[@]}" --names "$names" \
    --gbuffer "$dir/render/gbuffer.####.exr" --json "$dir/metrics.json" "${region_args[@]}" > /dev/null
  python3 "$TABLES" tuning-rows "$dir/metrics.json" "$name" "${runs[@]}" >> "$csv"
  python3 "$TABLES" tuning-region-rows "$dir/metrics.json" "$name" "${runs[@]}" >> "$region_csv"
  [[ "$KEEP_OUTPUTS" == 1 ]] || rm -rf "$dir/runs"
done <<< "$TUNE_SET"

python3 "$TABLES" tuning "$csv" > "$OUT/tuning.md"
if [[ ${#region_args[@]} -gt 0 ]]; then
  { echo "## Per region"; echo; python3 "$TABLES" tuning-regions "$region_csv"; } >> "$OUT/tuning.md"
  # Every run's arguments so far (APPEND=1 adds to the CSVs: the optimum may be a run of an earlier invocation).
  runs_file="$OUT/runs.txt"
  [[ "$APPEND" == 1 && -f "$runs_file" ]] || : > "$runs_file"
  printf '%s\n' "${runs[@]}" >> "$runs_file"
  mapfile -t all_runs < <(sort -u "$runs_file")
  python3 "$TABLES" tuned-variants "$region_csv" taa,ema "${all_runs[@]}" > "$OUT/tuned-variants.txt"
fi
cat "$OUT/tuning.md"
say "$OUT/tuning.md, $OUT/tuning.csv, $OUT/tuning-regions.csv, $OUT/tuned-variants.txt"
