#!/usr/bin/env bash
# Reproduction of seed 004 (Didyk et al. 2010): render built-in scenes at 40 Hz and at 120 Hz, upsample the 40 Hz
# stream to 120 Hz with every morph-120hz method (and ffmpeg's minterpolate when ffmpeg is installed), and report
#  - PSNR of the in-between frames (120 Hz frames 3n+1, 3n+2) against the native 120 Hz render (compare),
#  - the perceived-blur error: the image perceived on a hold-type display under smooth pursuit
#    (morph-120hz --perceive, seed 004 section 3) of each method against that of the native 120 Hz render, as PSNR,
#  - milliseconds per output frame (compute_ms of the headers; ffmpeg: wall time / frames, I/O included) and the
#    render time of one frame (render-gbuffer's timings.csv).
#
# Usage: pipelines/morph-120hz.sh [BUILD_DIR] [OUT_DIR] [SCENE.glb ...]
#   BUILD_DIR  default build/release;  OUT_DIR  default report/morph-120hz
#   SCENE      default: every assets/scenes/*.glb
# Environment: SIZE (default 256x256), FRAMES (rendered 40 Hz frames, default 8), METHODS (default: every
#   method of the registry, `morph-120hz --list-methods`), FFMPEG=0 to skip minterpolate.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=${1:-build/release}
OUT=${2:-report/morph-120hz}
shift $(( $# >= 2 ? 2 : $# ))
SIZE=${SIZE:-256x256}
FRAMES=${FRAMES:-8}
FACTOR=3

case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
RENDER="$BUILD/apps/render-gbuffer/render-gbuffer"
MORPH="$BUILD/apps/morph-120hz/morph-120hz"
COMPARE="$BUILD/apps/compare/compare"
for t in "$RENDER" "$MORPH" "$COMPARE"; do
  if [[ ! -x "$t" ]]; then
    echo "morph-120hz.sh: $t: not built; build it first (cmake --build $BUILD)" >&2
    exit 2
  fi
done
if (( FRAMES < 2 )); then echo "morph-120hz.sh: FRAMES must be at least 2" >&2; exit 1; fi
# The methods come from the tool's registry (one name and a tab-separated summary per line).
METHODS=${METHODS:-$("$MORPH" --list-methods | cut -f1 | tr '\n' ' ')}

if (( $# > 0 )); then SCENES=("$@"); else SCENES=("$ROOT"/assets/scenes/*.glb); fi
if [[ ! -e "${SCENES[0]}" ]]; then
  echo "morph-120hz.sh: no scene found (assets/scenes/*.glb is empty); pass SCENE.glb" >&2
  exit 2
fi

have_ffmpeg=0
if ! command -v oiiotool >/dev/null 2>&1; then
  echo "morph-120hz.sh: oiiotool not found: install openimageio-tools (it clamps the renders to [0, 1])" >&2
  exit 2
fi
if [[ "${FFMPEG:-1}" != 0 ]] && command -v ffmpeg >/dev/null 2>&1; then
  have_ffmpeg=1
else
  echo "morph-120hz.sh: ffmpeg not found (or FFMPEG=0): skipping the minterpolate baseline" >&2
fi

mkdir -p "$OUT"
LAST40=$((FRAMES - 1))
LAST120=$((FACTOR * FRAMES - 1))
# Compared frames: from the second rendered frame (rendered frame 0 is a camera cut with zero motion, so no
# method can extrapolate from it) to the last frame every method produces.
FIRSTCMP=$FACTOR
LASTCMP=$((FACTOR * FRAMES - 1))
TABLE="$OUT/summary.csv"
echo "scene,method,psnr_inbetween_db,psnr_all_db,perceived_psnr_db,ms_per_output_frame,render_ms_per_frame" > "$TABLE"

# mean of column NAME over the rows of CSV whose `sequence` is SEQ and whose frame passes FILTER (awk expr on f)
csv_mean() {
  local csv=$1 seq=$2 col=$3 filter=$4
  awk -F, -v seq="$seq" -v col="$col" "
    NR == 1 { for (i = 1; i <= NF; ++i) idx[\$i] = i; next }
    { f = \$idx[\"frame\"]; s = \$idx[\"sequence\"]; gsub(/\"/, \"\", s) }
    s == seq && ($filter) && \$idx[col] != \"\" && \$idx[col] != \"inf\" { sum += \$idx[col]; n++ }
    END { if (n) printf \"%.2f\", sum / n; else printf \"nan\" }" "$csv"
}

for scene in "${SCENES[@]}"; do
  name=$(basename "$scene"); name=${name%.*}
  D="$OUT/$name"
  echo "== $name: rendering $FRAMES frames at 40 Hz and $((LAST120 + 1)) at 120 Hz ($SIZE)" >&2
  "$RENDER" "$scene" --out "$D/r40" --fps 40 --frames "0-$LAST40" --size "$SIZE" --outputs gbuffer,color --jitter none
  "$RENDER" "$scene" --out "$D/r120" --fps 120 --frames "0-$LAST120" --size "$SIZE" --outputs gbuffer,color --jitter none
  # Seed 004 works on tone-mapped, display-referred frames (section 6: the blur runs on 8-bit RGB after tone
  # mapping). The scenes are scene-linear with highlights above 1: clamp both renders to [0, 1] first, so every
  # method (and ffmpeg, which clips anyway) and the reference see the same displayable frames.
  mkdir -p "$D/ldr40" "$D/ldr120"
  for ((n = 0; n <= LAST120; ++n)); do
    printf -v f "%04d" "$n"
    oiiotool "$D/r120/color.$f.exr" --ch R,G,B --clamp:min=0:max=1 -d float --compression zip -o "$D/ldr120/color.$f.exr"
    if (( n <= LAST40 )); then
      oiiotool "$D/r40/color.$f.exr" --ch R,G,B --clamp:min=0:max=1 -d float --compression zip -o "$D/ldr40/color.$f.exr"
    fi
  done
  # Render time of one frame: the sum of the pass columns of timings.csv, averaged over the 120 Hz frames.
  render_ms=$(awk -F, 'NR > 1 { s = 0; for (i = 3; i <= NF; ++i) s += $i; t += s; n++ } END { if (n) printf "%.2f", t / n; else printf "nan" }' "$D/r120/timings.csv")

  names=()
  tests=()
  for m in $METHODS; do
    echo "== $name: morph-120hz --method $m" >&2
    "$MORPH" --input "$D/ldr40/color.####.exr" --gbuffer "$D/r40/gbuffer.####.exr" --out "$D/$m/color.####.exr" \
      --method "$m" --factor $FACTOR --fps 40
    names+=("$m")
    tests+=("$D/$m/color.####.exr")
  done

  ffmpeg_ms=""
  if (( have_ffmpeg )); then
    echo "== $name: ffmpeg minterpolate" >&2
    # ffmpeg reads single-part EXR (not DWA): take the colour part as half/ZIP, interpolate, write float EXR.
    mkdir -p "$D/ffmpeg-in" "$D/minterpolate-raw" "$D/minterpolate"
    for ((n = 0; n <= LAST40; ++n)); do
      printf -v f "%04d" "$n"
      oiiotool "$D/ldr40/color.$f.exr" -d half --compression zip -o "$D/ffmpeg-in/c.$f.exr"
    done
    t0=$(date +%s.%N)
    ffmpeg -loglevel error -y -framerate 40 -start_number 0 -i "$D/ffmpeg-in/c.%04d.exr" \
      -vf "format=yuv444p,minterpolate=fps=120:mi_mode=mci:mc_mode=aobmc:me_mode=bidir:vsbmc=1" \
      -pix_fmt gbrpf32le -compression zip1 -start_number 0 "$D/minterpolate-raw/c.%04d.exr"
    t1=$(date +%s.%N)
    produced=$(ls "$D/minterpolate-raw" | wc -l)
    ffmpeg_ms=$(awk -v a="$t0" -v b="$t1" -v n="$produced" 'BEGIN { printf "%.2f", (b - a) * 1000 / (n > 0 ? n : 1) }')
    # Pad to the full 120 Hz range by holding the last frame, so compare sees a contiguous sequence.
    for ((n = 0; n <= LAST120; ++n)); do
      printf -v f "%04d" "$n"
      src="$D/minterpolate-raw/c.$f.exr"
      [[ -f "$src" ]] || src=$(ls "$D/minterpolate-raw"/c.*.exr | tail -1)
      cp "$src" "$D/minterpolate/color.$f.exr"
    done
    names+=("minterpolate")
    tests+=("$D/minterpolate/color.####.exr")
  fi

  echo "== $name: compare (in-between frames vs native 120 Hz)" >&2
  IFS=, ; name_list="${names[*]}"; unset IFS
  "$COMPARE" --reference "$D/ldr120/color.####.exr" "${tests[@]}" --names "$name_list" --frames "$FIRSTCMP-$LASTCMP" \
    --csv "$D/compare.csv" --json "$D/compare.json" --plot "$D/psnr.png"

  echo "== $name: perceived images (hold-type blur under smooth pursuit)" >&2
  "$MORPH" --perceive --input "$D/ldr120/color.####.exr" --gbuffer "$D/r120/gbuffer.####.exr" --frames "$FIRSTCMP-$LASTCMP" \
    --out "$D/perceived/native/p.####.exr"
  ptests=()
  for i in "${!names[@]}"; do
    m=${names[$i]}
    "$MORPH" --perceive --input "${tests[$i]}" --gbuffer "$D/r120/gbuffer.####.exr" --frames "$FIRSTCMP-$LASTCMP" \
      --out "$D/perceived/$m/p.####.exr"
    ptests+=("$D/perceived/$m/p.####.exr")
  done
  "$COMPARE" --reference "$D/perceived/native/p.####.exr" "${ptests[@]}" --names "$name_list" \
    --frames "$FIRSTCMP-$LASTCMP" --csv "$D/perceived.csv" --json "$D/perceived.json" --plot "$D/perceived.png"

  for m in "${names[@]}"; do
    inb=$(csv_mean "$D/compare.csv" "$m" psnr_rgb_db "f % $FACTOR != 0")
    all=$(csv_mean "$D/compare.csv" "$m" psnr_rgb_db "1")
    per=$(csv_mean "$D/perceived.csv" "$m" psnr_rgb_db "1")
    if [[ "$m" == minterpolate ]]; then ms=$ffmpeg_ms; else ms=$(csv_mean "$D/compare.csv" "$m" compute_ms "1"); fi
    echo "$name,$m,$inb,$all,$per,$ms,$render_ms" >> "$TABLE"
  done
done

echo
echo "Seed 004 reproduction ($SIZE, $FRAMES frames at 40 Hz -> 120 Hz). PSNR in dB against the native 120 Hz render;"
echo "perceived = PSNR of the smooth-pursuit perceived images; ms = compute per output frame (ffmpeg: wall, I/O incl.)."
column -s, -t < "$TABLE"
echo
echo "Table: $TABLE"
{
  echo "# morph-120hz: seed 004 on the built-in scenes"
  echo
  echo "$SIZE, $FRAMES frames at 40 Hz -> 120 Hz. PSNR in dB against the native 120 Hz render (in-between frames"
  echo "3n+1, 3n+2, and all frames); perceived = PSNR of the smooth-pursuit perceived images (hold-type blur, seed 004"
  echo "section 3) against those of the native 120 Hz render; ms = compute per output frame (ffmpeg: wall, I/O included);"
  echo "render ms = render-gbuffer per 40 Hz frame. Plots: <scene>/psnr*.png, <scene>/perceived*.png."
  echo
  echo "| scene | method | PSNR in-between | PSNR all | perceived PSNR | ms/output frame | render ms/frame |"
  echo "|---|---|---|---|---|---|---|"
  tail -n +2 "$TABLE" | sed 's/^/| /; s/,/ | /g; s/$/ |/'
} > "$OUT/summary.md"
