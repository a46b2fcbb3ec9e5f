#!/usr/bin/env bash
# Reproduction of seed 004 (Didyk et al. 2010): render built-in scenes at 40 Hz and at 120 Hz, upsample the 40 Hz
# stream to 120 Hz with every morph-120hz method (and ffmpeg's minterpolate when ffmpeg is installed), and report
#  - PSNR of the in-between frames (120 Hz frames 3n+1, 3n+2) against the native 120 Hz render (compare), both
#    latency-free (output frame t against native frame t) and latency-aware (against native frame t + L, the
#    instant it is shown; L = temporal:latencyFrames: blend and minterpolate 3, the others 0), each with compare's
#    95% bootstrap interval (compare --merge of the in-between rows) and the paired differences,
#  - the perceived-blur error: the image perceived on a hold-type display under smooth pursuit
#    (morph-120hz --perceive, seed 004 section 3) of each method against that of the native 120 Hz render, as PSNR,
#    as perceived and with the lag removed (--lag-reference: best shift along the motion), and the lag in ms,
#  - speed, like with like: compute per output frame (morph-120hz: temporal:computeMs of the headers, I/O
#    excluded; ffmpeg: its minterpolate run into the null muxer minus the same run with frame repetition instead
#    of minterpolate) and whole command per output frame (wall time of the morph-120hz and of the ffmpeg command,
#    EXR in and out, median of REPEAT runs), and the render time of one frame (render-gbuffer's timings.csv).
#
# Usage: pipelines/morph-120hz.sh [BUILD_DIR] [OUT_DIR] [SCENE.glb ...]
#   BUILD_DIR  default build/release;  OUT_DIR  default report/morph-120hz
#   SCENE      default: every assets/scenes/*.glb
# Environment: SIZE (default 256x256), FRAMES (rendered 40 Hz frames, default 8), METHODS (default: every
#   method of the registry, `morph-120hz --list-methods`), VARIANTS (more runs, one per line "NAME METHOD
#   morph-120hz options", e.g. "didyk-nosnap didyk --no-snap"; pipelines/morph-120hz-ablation.sh sets didyk's
#   ablations), FFMPEG=0 to skip minterpolate, REPEAT (timed runs of each command, default 3; the median is
#   reported), REGIONS (compare --regions for the in-between frames: motion (default) or none; STATIC_FRAMES its
#   --static-frames, default 10), PAIRS (paired differences per region, "A:B,..."; default didyk against repeat,
#   blend, warp and minterpolate, those run), NOISE_FLOOR_FRAMES (default 3; 0: none; see below).
#
# The in-between frames are scored by compare alone (--frames 3-Ly3: oiiotool's "all but every third"), so their
# means, 95 % intervals and paired differences are compare's and finite (a rendered frame repeats the native one
# exactly: PSNR inf). With --regions motion and the native 120 Hz G-buffer every metric is also split into static
# (still, with an unchanged reference, for STATIC_FRAMES 120 Hz frames), moving and disoccluded pixels (the
# reprojection test between consecutive 120 Hz frames fails): summary.md has the table per region and the paired
# differences per region. pipelines/morph-120hz-regions.sh splits the error further (the pixels that moved since
# the rendered frame a method extrapolates from, moving shadows on static surfaces), from this script's folders.
#
# The reference and its noise floor: the target is the native 120 Hz render by the same renderer as the 40 Hz
# input - one sample at every pixel centre (--jitter none), that instant's SSAO pattern and VPL set, clamped to
# [0, 1]. Antialiasing is not the task (the input is sampled at pixel centres too, and a method is right to
# reproduce its aliasing), but the per-instant SSAO / VPL noise of an in-between instant is something no method can
# predict from the rendered frames. So the 4x render of the noise floor is 4 samples at every pixel centre, each
# with its own SSAO pattern and VPL set (render-gbuffer --reference-jitter none --reference-spp 4), clamped the
# same way, of the first NOISE_FLOOR_FRAMES compared frames; summary.md prints PSNR(native, 4x) above the tables
# and says when the best in-between mean comes within 10 dB of it.
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

use_build "${1:-}"
OUT=${2:-report/morph-120hz}
shift $(( $# >= 2 ? 2 : $# ))
SIZE=${SIZE:-256x256}
FRAMES=${FRAMES:-8}
FACTOR=3
REPEAT=${REPEAT:-3}
WINDOW=3  # morph-120hz --perceive's default window
REGIONS=${REGIONS:-motion}
STATIC_FRAMES=${STATIC_FRAMES:-10}
NOISE_FLOOR_FRAMES=${NOISE_FLOOR_FRAMES:-3}
PAIRS=${PAIRS:-didyk:repeat,didyk:blend,didyk:warp,didyk:minterpolate}

require_tools render-gbuffer morph-120hz compare
RENDER="$(tool_path render-gbuffer)"
MORPH="$(tool_path morph-120hz)"
COMPARE="$(tool_path compare)"
if (( FRAMES < 2 )); then die "FRAMES must be at least 2" 1; fi
region_args=()
if [[ "$REGIONS" != none ]]; then region_args=(--regions "$REGIONS" --static-frames "$STATIC_FRAMES"); fi
# The methods come from the tool's registry.
METHODS=${METHODS:-$(methods_of morph-120hz)}
# Every run: "NAME ARGUMENTS" (the METHODS through the registry, then the VARIANTS lines).
RUNS=()
add_runs morph-120hz RUNS

if (( $# > 0 )); then SCENES=("$@"); else SCENES=("$ROOT"/assets/scenes/*.glb); fi
if [[ ! -e "${SCENES[0]}" ]]; then
  die "no scene found (assets/scenes/*.glb is empty); pass SCENE.glb"
fi

have_ffmpeg=0
command -v oiiotool >/dev/null 2>&1 && command -v iinfo >/dev/null 2>&1 ||
  die "oiiotool or iinfo not found: install openimageio-tools (oiiotool clamps the renders to [0, 1], iinfo reads the lag headers)"
if [[ "${FFMPEG:-1}" != 0 ]] && command -v ffmpeg >/dev/null 2>&1; then
  have_ffmpeg=1
else
  say "ffmpeg not found (or FFMPEG=0): skipping the minterpolate baseline"
fi

mkdir -p "$OUT"
LAST40=$((FRAMES - 1))
LAST120=$((FACTOR * FRAMES - 1))
# Compared frames: from the second rendered frame (rendered frame 0 is a camera cut with zero motion, so no
# method can extrapolate from it) to the last frame every method produces.
FIRSTCMP=$FACTOR
LASTCMP=$((FACTOR * FRAMES - 1))
# The native render goes on past the last output frame: a method with one rendered frame of latency shows output
# frame LASTCMP at LASTCMP + FACTOR (latency-aware scoring), and the eye integrates WINDOW - 1 frames further.
LASTNATIVE=$((LASTCMP + FACTOR + WINDOW - 1))
TABLE="$OUT/summary.csv"
PAIRED="$OUT/paired.csv"
echo "scene,method,latency_frames,psnr_inbetween_db,psnr_inbetween_ci_low,psnr_inbetween_ci_high,psnr_inbetween_latency_db,psnr_inbetween_latency_ci_low,psnr_inbetween_latency_ci_high,psnr_all_db,perceived_psnr_db,perceived_latency_psnr_db,perceived_blur_psnr_db,lag_ms,compute_ms_per_output_frame,command_ms_per_output_frame,render_ms_per_frame" > "$TABLE"
echo "scene,score,metric,a,b,frames,mean_difference_db,ci_low,ci_high" > "$PAIRED"

# Median wall time in ms of REPEAT runs of a command (its output to /dev/null unless redirected inside). The
# median is tables.py's (a number compare does not compute: the whole command's wall time).
median_ms() {
  local r
  for ((r = 0; r < REPEAT; ++r)); do
    local t0 t1
    t0=$(date +%s.%N)
    "$@" >&2
    t1=$(date +%s.%N)
    echo "$t0 $t1"
  done | python3 "$TABLES" median-ms
}

# sequence METRIC -> "mean,ci_low,ci_high" from compare's JSON (empty fields when absent)
json_interval() { python3 "$TABLES" interval "$@"; }

# Paired differences a - b of one metric from compare's JSON, as rows of paired.csv.
json_paired() { python3 "$TABLES" paired-rows "$@"; }

# `temporal:KEY` of each EXR header, one line per file in order (empty where the file lacks it): one iinfo for all
# the files (one `oiiotool --info` per file: 7.3 s for 20 files on the 2-core VM, iinfo 0.24 s). iinfo -v starts each file's listing with an unindented
# "FILE : W x H, ..." line and indents its attributes.
header_values() {
  local key=$1
  shift
  iinfo -v "$@" 2>/dev/null | awk -v key="temporal:$key" '
    /^[^ \t]/ { if (seen) print v; seen = 1; v = "" }
    $1 == key":" { v = $2; gsub(/"/, "", v) }
    END { if (seen) print v }'
}

SCENE_NAMES=()
for scene in "${SCENES[@]}"; do
  name=$(basename "$scene"); name=${name%.*}
  SCENE_NAMES+=("$name")
  D="$OUT/$name"
  echo "== $name: rendering $FRAMES frames at 40 Hz and $((LASTNATIVE + 1)) at 120 Hz ($SIZE)" >&2
  "$RENDER" "$scene" --out "$D/r40" --fps 40 --frames "0-$LAST40" --size "$SIZE" --outputs gbuffer,color --jitter none
  "$RENDER" "$scene" --out "$D/r120" --fps 120 --frames "0-$LASTNATIVE" --size "$SIZE" --outputs gbuffer,color --jitter none
  # Seed 004 works on tone-mapped, display-referred frames (section 6: the blur runs on 8-bit RGB after tone
  # mapping). The scenes are scene-linear with highlights above 1: clamp both renders to [0, 1] first, so every
  # method (and ffmpeg, which clips anyway) and the reference see the same displayable frames.
  mkdir -p "$D/ldr40" "$D/ldr120"
  for ((n = 0; n <= LASTNATIVE; ++n)); do
    printf -v f "%04d" "$n"
    oiiotool "$D/r120/color.$f.exr" --ch R,G,B --clamp:min=0:max=1 -d float --compression zip -o "$D/ldr120/color.$f.exr"
    if (( n <= LAST40 )); then
      oiiotool "$D/r40/color.$f.exr" --ch R,G,B --clamp:min=0:max=1 -d float --compression zip -o "$D/ldr40/color.$f.exr"
    fi
  done
  # Render time of one frame: the sum of the pass columns of timings.csv, averaged over the 120 Hz frames.
  render_ms=$(python3 "$TABLES" pass-ms-mean "$D/r120/timings.csv")

  names=()
  tests=()
  declare -A command_ms=() compute_ms=()
  for run in "${RUNS[@]}"; do
    read -r m args <<< "$run"
    echo "== $name: $m = morph-120hz $args ($REPEAT timed runs)" >&2
    # shellcheck disable=SC2086
    wall=$(median_ms "$MORPH" --input "$D/ldr40/color.####.exr" --gbuffer "$D/r40/gbuffer.####.exr" \
      --out "$D/$m/color.####.exr" $args --factor $FACTOR --fps 40)
    command_ms[$m]=$(python3 "$TABLES" per-frame "$wall" $((FACTOR * FRAMES)))
    names+=("$m")
    tests+=("$D/$m/color.####.exr")
  done

  if (( have_ffmpeg )); then
    echo "== $name: ffmpeg minterpolate" >&2
    # ffmpeg reads single-part EXR (not DWA): take the colour part as half/ZIP, interpolate, write float EXR.
    mkdir -p "$D/ffmpeg-in" "$D/minterpolate-raw" "$D/minterpolate"
    for ((n = 0; n <= LAST40; ++n)); do
      printf -v f "%04d" "$n"
      oiiotool "$D/ldr40/color.$f.exr" -d half --compression zip -o "$D/ffmpeg-in/c.$f.exr"
    done
    mi="minterpolate=fps=120:mi_mode=mci:mc_mode=aobmc:me_mode=bidir:vsbmc=1"
    # Whole command: EXR in, minterpolate, EXR out (as morph-120hz's whole command: EXR in and out).
    wall=$(median_ms ffmpeg -loglevel error -y -framerate 40 -start_number 0 -i "$D/ffmpeg-in/c.%04d.exr" \
      -vf "format=yuv444p,$mi" -pix_fmt gbrpf32le -compression zip1 -start_number 0 "$D/minterpolate-raw/c.%04d.exr")
    produced=$(ls "$D/minterpolate-raw" | wc -l)
    # Compute: the same decode and pixel-format conversions into the null muxer, with minterpolate and with plain
    # frame repetition (fps=120) in its place; the difference is minterpolate's own time.
    with_mi=$(median_ms ffmpeg -loglevel error -y -framerate 40 -start_number 0 -i "$D/ffmpeg-in/c.%04d.exr" \
      -vf "format=yuv444p,$mi,format=gbrpf32le" -f null -)
    without_mi=$(median_ms ffmpeg -loglevel error -y -framerate 40 -start_number 0 -i "$D/ffmpeg-in/c.%04d.exr" \
      -vf "format=yuv444p,fps=120,format=gbrpf32le" -f null -)
    command_ms[minterpolate]=$(python3 "$TABLES" per-frame "$wall" "$produced")
    compute_ms[minterpolate]=$(python3 "$TABLES" per-frame "$with_mi" "$produced" "$without_mi")
    # Pad to the full 120 Hz range by holding the last frame, so compare sees a contiguous sequence; declare
    # minterpolate's latency (it interpolates towards the next rendered frame: one rendered frame, FACTOR output
    # frames) and the rate, as morph-120hz's headers do.
    for ((n = 0; n <= LAST120; ++n)); do
      printf -v f "%04d" "$n"
      src="$D/minterpolate-raw/c.$f.exr"
      [[ -f "$src" ]] || src=$(ls "$D/minterpolate-raw"/c.*.exr | tail -1)
      oiiotool "$src" --sattrib temporal:latencyFrames $FACTOR --attrib:type=float temporal:fps 120 \
        --sattrib temporal:method minterpolate -d float --compression zip -o "$D/minterpolate/color.$f.exr"
    done
    names+=("minterpolate")
    tests+=("$D/minterpolate/color.####.exr")
  fi

  echo "== $name: compare (in-between frames vs native 120 Hz)" >&2
  IFS=, ; name_list="${names[*]}"; unset IFS
  # The PAIRS whose two sequences ran.
  pair_list=""
  for p in ${PAIRS//,/ }; do
    [[ ",$name_list," == *",${p%%:*},"* && ",$name_list," == *",${p#*:},"* ]] && pair_list+="${pair_list:+,}$p"
  done
  "$COMPARE" --reference "$D/ldr120/color.####.exr" "${tests[@]}" --names "$name_list" --frames "$FIRSTCMP-$LASTCMP" \
    --latency-aware --csv "$D/compare.csv" --json "$D/compare.json" --plot "$D/psnr.png"
  # The in-between frames alone (3n+1, 3n+2: "all but every third"), with their intervals, paired differences and,
  # with REGIONS=motion, every metric per region of the native 120 Hz G-buffer.
  echo "== $name: compare (in-between frames${region_args[*]:+, per region})" >&2
  "$COMPARE" --reference "$D/ldr120/color.####.exr" "${tests[@]}" --names "$name_list" \
    --frames "$FIRSTCMP-${LASTCMP}y$FACTOR" --latency-aware --gbuffer "$D/r120/gbuffer.####.exr" "${region_args[@]}" \
    --csv "$D/inbetween.csv" --json "$D/inbetween.json" --plot "$D/inbetween.png" > "$D/inbetween.txt"

  # The reference's noise floor (see the header): the native 120 Hz render's first NOISE_FLOOR_FRAMES compared
  # frames at 4 samples per pixel centre, clamped as ldr120 is (lib.sh noise_floor_render / noise_floor_score).
  if (( NOISE_FLOOR_FRAMES > 0 )); then
    floor_range="$(floor_frames "$FIRSTCMP-$LASTCMP" "$NOISE_FLOOR_FRAMES")"
    noise_floor_render "$scene" "$D/r120-4x" "$floor_range" 4 --fps 120 --size "$SIZE" --reference-jitter none
    mkdir -p "$D/ldr120-4x"
    for ((n = ${floor_range%-*}; n <= ${floor_range#*-}; ++n)); do
      printf -v f "%04d" "$n"
      oiiotool "$D/r120-4x/reference.$f.exr" --ch R,G,B --clamp:min=0:max=1 -d float --compression zip \
        -o "$D/ldr120-4x/reference.$f.exr"
    done
    noise_floor_score "$D/ldr120/color.####.exr" "$D/ldr120-4x/reference.####.exr" "$floor_range" "$D/noise-floor.json"
  fi

  echo "== $name: perceived images (hold-type blur under smooth pursuit)" >&2
  # The native stream's perceived images through LASTCMP + FACTOR (for the latency-aware score of a test shown
  # FACTOR frames late); they are also the lag reference.
  "$MORPH" --perceive --input "$D/ldr120/color.####.exr" --gbuffer "$D/r120/gbuffer.####.exr" \
    --frames "$FIRSTCMP-$((LASTCMP + FACTOR))" --out "$D/perceived/native/p.####.exr"
  ptests=()
  for i in "${!names[@]}"; do
    m=${names[$i]}
    "$MORPH" --perceive --input "${tests[$i]}" --gbuffer "$D/r120/gbuffer.####.exr" --frames "$FIRSTCMP-$LASTCMP" \
      --lag-reference "$D/perceived/native/p.####.exr" --out "$D/perceived/$m/p.####.exr"
    ptests+=("$D/perceived/$m/p.####.exr")
  done
  # As perceived (latency-free psnr_rgb, and psnr_latency against the native perceived image at the instant
  # shown), and with the lag removed (layer aligned: aligned to native perceived frame t by the best shift along
  # the motion; its psnr_rgb is the blur score).
  "$COMPARE" --reference "$D/perceived/native/p.####.exr" "${ptests[@]}" --names "$name_list" \
    --frames "$FIRSTCMP-$LASTCMP" --latency-aware --csv "$D/perceived.csv" --json "$D/perceived.json" --plot "$D/perceived.png"
  "$COMPARE" --reference "$D/perceived/native/p.####.exr" "${ptests[@]}" --names "$name_list" --layer aligned \
    --reference-layer rgb --frames "$FIRSTCMP-$LASTCMP" --csv "$D/perceived-blur.csv" \
    --json "$D/perceived-blur.json" > /dev/null

  json_paired "$D/inbetween.json" "$name" inbetween psnr_rgb >> "$PAIRED"
  json_paired "$D/inbetween.json" "$name" inbetween_latency psnr_latency >> "$PAIRED"
  json_paired "$D/perceived-blur.json" "$name" perceived_blur psnr_rgb >> "$PAIRED"
  for m in "${names[@]}"; do
    inb=$(json_interval "$D/inbetween.json" "$m" psnr_rgb)
    inb_lat=$(json_interval "$D/inbetween.json" "$m" psnr_latency)
    all=$(json_interval "$D/compare.json" "$m" psnr_rgb | cut -d, -f1)  # "inf" when a frame is identical
    latency=$(python3 "$TABLES" value "$D/compare.json" "$m" psnr_latency.latency_frames 0)
    # compare's means: a frame of infinite PSNR (an identical image) makes the mean "inf" - shown, never dropped.
    per=$(json_interval "$D/perceived.json" "$m" psnr_rgb | cut -d, -f1)
    per_lat=$(json_interval "$D/perceived.json" "$m" psnr_latency | cut -d, -f1)
    blur=$(json_interval "$D/perceived-blur.json" "$m" psnr_rgb | cut -d, -f1)
    # Mean lag over the compared frames, from the perceived images' headers (temporal:lagMs).
    # (A number compare does not compute: tables.py's mean of the header values.)
    lag_files=()
    for ((n = FIRSTCMP; n <= LASTCMP; ++n)); do printf -v f "%04d" "$n"; lag_files+=("$D/perceived/$m/p.$f.exr"); done
    lag=$(header_values lagMs "${lag_files[@]}" | python3 "$TABLES" mean)
    # compare's mean compute_ms over the compared frames (minterpolate's: the ffmpeg difference above).
    if [[ "$m" == minterpolate ]]; then ms=${compute_ms[$m]}; else ms=$(python3 "$TABLES" value "$D/compare.json" "$m" compute_ms 2); fi
    echo "$name,$m,$latency,$inb,$inb_lat,$all,$per,$per_lat,$blur,$lag,$ms,${command_ms[$m]},$render_ms" >> "$TABLE"
  done
  unset command_ms compute_ms
done

echo
echo "Seed 004 reproduction ($SIZE, $FRAMES frames at 40 Hz -> 120 Hz). PSNR in dB against the native 120 Hz render;"
echo "perceived = PSNR of the smooth-pursuit perceived images (blur: lag removed); compute = the method's own time per"
echo "output frame (I/O excluded), command = wall time of the whole command per output frame (EXR in and out)."
column -s, -t < "$TABLE"
echo
echo "Table: $TABLE"
{
  echo "# morph-120hz: seed 004 on the built-in scenes"
  echo
  echo "$SIZE, $FRAMES frames at 40 Hz -> 120 Hz. PSNR in dB against the native 120 Hz render (in-between frames"
  echo "3n+1, 3n+2 [95% interval], latency-free and at the instant shown; all frames); perceived = PSNR of the"
  echo "smooth-pursuit perceived images (hold-type blur, seed 004 section 3) against those of the native 120 Hz render"
  echo "(as perceived, at the instant shown, and with the lag removed), lag in ms; compute = the method's own time per"
  echo "output frame (I/O excluded), command = whole command per output frame (EXR in and out); render ms ="
  echo "render-gbuffer per 120 Hz frame. Paired differences: paired.csv. Plots: <scene>/psnr*.png, <scene>/inbetween*.png (per region too),"
  echo "<scene>/perceived*.png."
  echo
  python3 "$TABLES" morph-summary "$TABLE"
  echo
  if (( NOISE_FLOOR_FRAMES > 0 )); then
    echo "The reference's noise floor per scene (the native 120 Hz render against 4 samples at every pixel centre,"
    echo "the SSAO / VPL noise averaged; the best score is the best in-between mean, latency-free):"
    echo
    for s in "${SCENE_NAMES[@]}"; do
      echo "- $s: $(python3 "$TABLES" noise-floor "$OUT/$s/noise-floor.json" "$OUT/$s/inbetween.json" 1 4)"
    done
    echo
  fi
  if [[ "$REGIONS" != none ]]; then
    echo "In-between frames per region of the native 120 Hz G-buffer (compare --frames $FIRSTCMP-${LASTCMP}y$FACTOR"
    echo "--regions $REGIONS --static-frames $STATIC_FRAMES, latency-free):"
    python3 "$TABLES" region-table "$OUT" inbetween.json "$(IFS=,; echo "${SCENE_NAMES[*]}")" "$name_list" "$pair_list"
  fi
} > "$OUT/summary.md"
if [[ "$REGIONS" != none ]]; then
  python3 "$TABLES" region-table "$OUT" inbetween.json "$(IFS=,; echo "${SCENE_NAMES[*]}")" "$name_list" "$pair_list"
fi
