#!/usr/bin/env bash
# Reproduces seed 000's Table 1 and Figure 8 (Herzog et al. 2010, "Spatio-Temporal Upsampling on the GPU") on the
# built-in scenes: each scene is rendered by render-gbuffer (full-resolution G-buffer, the payload at 1/4 x 1/4
# under the regular 4x4 jitter pattern, and the same payload at full resolution, one sample at each pixel centre),
# every upsample-st method rebuilds the full-resolution payload, and compare reports PSNR per frame against the
# full-resolution payload (Figure 8's measure, as PNG charts) and the table of Table 1: per method,
# low-resolution shading ms + upsampling ms next to the full-resolution shading ms, and mean PSNR.
#
# Usage: pipelines/upsample-st.sh [BUILD_DIR] [OUT_DIR] [SCENE.glb ...]
#   BUILD_DIR  where the tools were built (default build/release)
#   OUT_DIR    report folder (default report/upsample-st)
#   SCENE      scenes to run (default: the built-in walkers (the horses scene), tower and fan of assets/scenes)
# Environment: SIZE (default 640x512; the paper used 1280x1024), FRAMES (default 0-47), FPS (default 30),
#   FACTOR (default 4), METHODS (default "spatial temporal herzog herzog-favor-spatial drobot taau spatial-demod
#   herzog-demod"; names of the method table as `upsample-st --list-methods` prints them: a method, a named variant
#   such as herzog-lagged (--lagged-wf), herzog-favor-spatial (a = 0.7, the paper's elephant scene) or
#   drobot-refresh (--mode refresh), optionally with a suffix the table lists, such as -demod (--demodulate:
#   lighting upsampled, albedo from the G-buffer; seed 000 section 4)), REFERENCE_SPP (default 0: none; N > 0 also
#   renders an N-spp supersampled reference and
#   adds a PSNR column against it), RENDER_ARGS (extra render-gbuffer options; default "--payload
#   direct,shadow,ssao,gi", Table 1's "Horses (AO+GI)"), UPSAMPLE_ARGS (extra upsample-st options for every method),
#   VARIANTS (more runs, one per line "NAME METHOD upsample-st options", e.g. "herzog-cap8 herzog --kernel-gamma 8
#   --max-kernel-gamma 8"; a NAME ending in -raster runs on the payload rendered with the raster pattern order,
#   --shade-jitter regular-raster, which is then rendered too), PAIRS (paired differences "A:B,..." printed with
#   their 95 % intervals; default herzog against spatial, temporal and taau), WARMUP (frames compare reports apart
#   as the warm-up, default FACTOR^2: the pattern's length), NOISE_AVERAGED_SPP (default 0; N > 0 also renders the
#   noise-averaged reference - N samples at every pixel centre, each with its own SSAO pattern and VPL set,
#   render-gbuffer --reference-jitter none - and scores every method against it too: the target of methods that
#   accumulate, issue 15 item 6), REGIONS (compare --regions for the main comparison: motion (default) or none;
#   STATIC_FRAMES its --static-frames, default 10), RENDERS (folder holding SCENE/render, default OUT_DIR), REUSE_RENDER=1 (keep an
#   existing render folder), NOISE_FLOOR_FRAMES (default 3; 0: none): the first N frames of each reference are
#   rendered again at 4x its samples and compare scores the reference against them (its noise floor, issue 24),
#   printed above the scene's table with a note when the best mean PSNR comes within 10 dB of it.
#
# Noise floors (which 4x render each reference is measured against): the full-resolution payload (`color`, one
# sample at each pixel centre with that frame's SSAO pattern and VPL set) against 4 samples at every pixel centre,
# each with its own SSAO pattern and VPL set (render-gbuffer --reference-jitter none --reference-spp 4): the
# payload's own per-frame noise, which a method that accumulates averages away and is then scored down for; the
# noise-averaged reference (NOISE_AVERAGED_SPP = N) against 4N samples at the pixel centres (--reference-jitter
# none again: the issue 24 audit's choice for this task, since upsample-st reconstructs the payload at pixel
# centres and is not asked to antialias); the supersampled reference (REFERENCE_SPP = N) against 4N Halton samples.
#
# Ground truth: the issue and the paper's Figure 8 measure against full-resolution rendering of the same payload
# (render-gbuffer's `color` with `--jitter none`: one sample at every pixel centre, the samples the regular
# pattern visits). A supersampled reference also scores the aliasing of that full-resolution payload itself and
# the per-frame SSAO / VPL noise, which no upsampler is asked to remove; it is optional.
#
# Costs: shading ms are render-gbuffer's `shadeLow` (payload at 1/FACTOR resolution) and `shadeFull` (the same
# payload at full resolution) from timings.csv, upsampling ms are upsample-st's `temporal:computeMs` (compare's
# mean over frames, from its JSON). Both are measured on this machine (llvmpipe for the shading). The tables are
# pipelines/tables.py's; herzog's margins are compare's paired differences.
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

use_build "${1:-}"
OUT="${2:-report/upsample-st}"
shift $(( $# > 2 ? 2 : $# ))
SIZE="${SIZE:-640x512}"
FRAMES="${FRAMES:-0-47}"
FPS="${FPS:-30}"
FACTOR="${FACTOR:-4}"
METHODS="${METHODS:-spatial temporal herzog herzog-favor-spatial drobot taau spatial-demod herzog-demod}"
REFERENCE_SPP="${REFERENCE_SPP:-0}"
RENDER_ARGS="${RENDER_ARGS:---payload direct,shadow,ssao,gi}"
UPSAMPLE_ARGS="${UPSAMPLE_ARGS:-}"
VARIANTS="${VARIANTS:-}"
PAIRS="${PAIRS:-herzog:spatial,herzog:temporal,herzog:taau}"
WARMUP="${WARMUP:-$(( FACTOR * FACTOR ))}"
NOISE_AVERAGED_SPP="${NOISE_AVERAGED_SPP:-0}"
RENDERS="${RENDERS:-}"
REUSE_RENDER="${REUSE_RENDER:-0}"
NOISE_FLOOR_FRAMES="${NOISE_FLOOR_FRAMES:-3}"
if [[ "$REFERENCE_SPP" -gt 0 && "$NOISE_AVERAGED_SPP" -gt 0 ]]; then
  die "REFERENCE_SPP and NOISE_AVERAGED_SPP both need render-gbuffer's reference output: set one" 1
fi

require_tools render-gbuffer upsample-st compare
upsample="$(tool_path upsample-st)"
compare="$(tool_path compare)"
# Every metric also per region (static / moving / disoccluded, from the G-buffer; docs/compare.md "Regions").
REGIONS="${REGIONS:-motion}"
region_args=()
if [[ "$REGIONS" != none && "$("$compare" --help 2>/dev/null || true)" == *--regions* ]]; then
  region_args=(--regions "$REGIONS" --static-frames "${STATIC_FRAMES:-10}")
fi

# Every run: "NAME ARGUMENTS" (METHODS through the method table, then the VARIANTS lines as given).
runs=()
add_runs upsample-st runs
raster=0
for run in "${runs[@]}"; do
  if [[ "${run%% *}" == *-raster ]]; then raster=1; fi
done
IFS=, read -r -a pairs <<< "$PAIRS"

use_scenes "walkers tower fan" "$@"

mkdir -p "$OUT"
summary="$OUT/summary.md"
{
  echo "# upsample-st: seed 000 Table 1 / Figure 8 on the built-in scenes"
  echo
  echo "Size $SIZE, factor $FACTOR, frames $FRAMES at $FPS fps; render options: $RENDER_ARGS."
  echo "shade = render-gbuffer shadeLow (1/$FACTOR payload), up = upsample-st compute ms, full = shadeFull"
  ss_note="."
  [[ "$REFERENCE_SPP" -gt 0 ]] && ss_note=" (and against a $REFERENCE_SPP-spp supersampled reference)."
  echo "(payload at full resolution); PSNR (RGB, dB, mean over frames) against the full-resolution payload$ss_note"
  echo
} > "$summary"

outputs="gbuffer,shade,color"
reference_args=(--reference-spp 1)
if [[ "$REFERENCE_SPP" -gt 0 ]]; then
  outputs+=",reference"
  reference_args=(--reference-spp "$REFERENCE_SPP")
elif [[ "$NOISE_AVERAGED_SPP" -gt 0 ]]; then
  outputs+=",reference"
  reference_args=(--reference-spp "$NOISE_AVERAGED_SPP" --reference-jitter none)
fi
scene_names=""
seq_names=""
for run in "${runs[@]}"; do read -r n _ <<< "$run"; seq_names+="${seq_names:+,}$n"; done
for scene in "${scenes[@]}"; do
  name="$(basename "${scene%.*}")"
  scene_names+="${scene_names:+,}$name"
  dir="$OUT/$name"
  render_dir="${RENDERS:-$OUT}/$name/render"
  mkdir -p "$dir"
  # shellcheck disable=SC2086
  render_or_reuse "$name" "$render_dir" "($SIZE, factor $FACTOR, frames $FRAMES)" "$scene" --size "$SIZE" \
    --fps "$FPS" --frames "$FRAMES" --factor "$FACTOR" --outputs "$outputs" --jitter none "${reference_args[@]}" \
    $RENDER_ARGS
  if [[ "$raster" == 1 ]]; then
    # shellcheck disable=SC2086
    render_or_reuse "$name" "$render_dir-raster" "the payload in the raster pattern order" "$scene" --size "$SIZE" \
      --fps "$FPS" --frames "$FRAMES" --factor "$FACTOR" --outputs shade --shade-jitter regular-raster $RENDER_ARGS
  fi

  tests=()
  for run in "${runs[@]}"; do
    read -r m args <<< "$run"
    input="$render_dir/shade.####.exr"
    [[ "$m" == *-raster ]] && input="$render_dir-raster/shade.####.exr"
    echo "== $name: $m = upsample-st $args" >&2
    # shellcheck disable=SC2086
    "$upsample" --gbuffer "$render_dir/gbuffer.####.exr" --input "$input" \
      --out "$dir/$m/up-$m.####.exr" $args $UPSAMPLE_ARGS
    tests+=("$dir/$m/up-$m.####.exr")
  done

  # Means over frames with 95 % intervals, the warm-up (the first FACTOR^2 frames) apart, and every paired
  # difference (compare's JSON, docs/compare.md "Intervals").
  echo "== $name: compare against the full-resolution payload" >&2
  "$compare" --reference "$render_dir/color.####.exr" "${tests[@]}" --names "$seq_names" \
    --gbuffer "$render_dir/gbuffer.####.exr" --csv "$dir/metrics.csv" --json "$dir/metrics.json" \
    --warmup "$WARMUP" --plot "$dir/psnr.png" "${region_args[@]}" | tee "$dir/compare.txt"
  if [[ "$REFERENCE_SPP" -gt 0 ]]; then
    echo "== $name: compare against the $REFERENCE_SPP-spp reference" >&2
    "$compare" --reference "$render_dir/reference.####.exr" "${tests[@]}" --names "$seq_names" \
      --csv "$dir/metrics-supersampled.csv" --json "$dir/metrics-supersampled.json" | tee "$dir/compare-supersampled.txt"
  fi
  if [[ "$NOISE_AVERAGED_SPP" -gt 0 ]]; then
    echo "== $name: compare against the noise-averaged payload ($NOISE_AVERAGED_SPP samples at the pixel centres)" >&2
    mkdir -p "$OUT/noise-averaged/$name"
    "$compare" --reference "$render_dir/reference.####.exr" "${tests[@]}" --names "$seq_names" \
      --gbuffer "$render_dir/gbuffer.####.exr" --csv "$OUT/noise-averaged/$name/metrics.csv" \
      --json "$OUT/noise-averaged/$name/metrics.json" --warmup "$WARMUP" --plot "$OUT/noise-averaged/$name/psnr.png" \
      "${region_args[@]}" | tee "$dir/compare-noise-averaged.txt"
  fi

  # The noise floor of each reference scored against (see the header): the reference's first NOISE_FLOOR_FRAMES
  # frames at 4x its samples (lib.sh noise_floor_render / noise_floor_score), the line tables.py noise-floor prints.
  floors=()
  if [[ "$NOISE_FLOOR_FRAMES" -gt 0 ]]; then
    floor_range="$(floor_frames "$FRAMES" "$NOISE_FLOOR_FRAMES")"
    floor_root="${RENDERS:-$OUT}/$name"
    # shellcheck disable=SC2086
    noise_floor_render "$scene" "$floor_root/floor-payload" "$floor_range" 4 --size "$SIZE" --fps "$FPS" \
      --reference-jitter none $RENDER_ARGS
    noise_floor_score "$render_dir/color.####.exr" "$floor_root/floor-payload/reference.####.exr" "$floor_range" \
      "$dir/noise-floor.json"
    floors+=("full-resolution payload|$dir/noise-floor.json|$dir/metrics.json|1|4")
    if [[ "$NOISE_AVERAGED_SPP" -gt 0 ]]; then
      # shellcheck disable=SC2086
      noise_floor_render "$scene" "$floor_root/floor-noise-averaged" "$floor_range" $(( 4 * NOISE_AVERAGED_SPP )) \
        --size "$SIZE" --fps "$FPS" --reference-jitter none $RENDER_ARGS
      noise_floor_score "$render_dir/reference.####.exr" "$floor_root/floor-noise-averaged/reference.####.exr" \
        "$floor_range" "$OUT/noise-averaged/$name/noise-floor.json"
      floors+=("noise-averaged reference|$OUT/noise-averaged/$name/noise-floor.json|$OUT/noise-averaged/$name/metrics.json|$NOISE_AVERAGED_SPP|$(( 4 * NOISE_AVERAGED_SPP ))")
    fi
    if [[ "$REFERENCE_SPP" -gt 0 ]]; then
      # shellcheck disable=SC2086
      noise_floor_render "$scene" "$floor_root/floor-supersampled" "$floor_range" $(( 4 * REFERENCE_SPP )) \
        --size "$SIZE" --fps "$FPS" $RENDER_ARGS
      noise_floor_score "$render_dir/reference.####.exr" "$floor_root/floor-supersampled/reference.####.exr" \
        "$floor_range" "$dir/noise-floor-supersampled.json"
      floors+=("supersampled reference|$dir/noise-floor-supersampled.json|$dir/metrics-supersampled.json|$REFERENCE_SPP|$(( 4 * REFERENCE_SPP ))")
    fi
  fi

  # The shading ms: render-gbuffer's timings.csv, which compare does not read (tables.py, "Numbers compare does
  # not compute").
  shade_low="$(python3 "$TABLES" csv-mean "$render_dir/timings.csv" shadeLow)"
  shade_full="$(python3 "$TABLES" csv-mean "$render_dir/timings.csv" shadeFull)"
  ss=()
  [[ "$REFERENCE_SPP" -gt 0 ]] && ss=("$dir/metrics-supersampled.json" "$REFERENCE_SPP spp")
  {
    echo "## $name"
    echo
    for f in "${floors[@]}"; do
      IFS='|' read -r label floor_json metrics_json spp spp4 <<< "$f"
      echo "Against the $label: $(python3 "$TABLES" noise-floor "$floor_json" "$metrics_json" "$spp" "$spp4")"
      echo
    done
    python3 "$TABLES" upsample-st "$dir" "$shade_low" "$shade_full" "${ss[@]}"
    echo
    echo "Per-frame PSNR: $name/psnr.png; metrics: $name/metrics.csv, $name/metrics.json."
    echo
  } >> "$summary"
done

pair_args=""
for p in "${pairs[@]}"; do
  a="${p%%:*}" b="${p#*:}"
  [[ ",$seq_names," == *",$a,"* && ",$seq_names," == *",$b,"* ]] && pair_args+="${pair_args:+,}$p"
done
{
  echo "## Mean PSNR (RGB, dB) [95% interval] (steady state: after the first $WARMUP frames) / mean flicker"
  echo
  echo "Against the full-resolution payload (that frame's SSAO pattern and VPL set):"
  echo
  python3 "$TABLES" scenes-by-row "$OUT" "$scene_names" "$seq_names" "$pair_args"
  echo
  if [[ "$NOISE_AVERAGED_SPP" -gt 0 ]]; then
    echo "Against the noise-averaged payload ($NOISE_AVERAGED_SPP samples at every pixel centre, each with its own SSAO"
    echo "pattern and VPL set):"
    echo
    python3 "$TABLES" scenes-by-row "$OUT/noise-averaged" "$scene_names" "$seq_names" "$pair_args"
    echo
  fi
} >> "$summary"

echo
cat "$summary"
say "report in $OUT (summary.md, per scene: metrics.csv, metrics.json, psnr*.png)"
