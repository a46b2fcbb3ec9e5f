#!/usr/bin/env bash
# Runs pipelines/upsample-st.sh on a tiny render of the built-in tower scene (64x48, 6 frames, every payload
# term, a 2-spp supersampled reference) and checks its summary: one table row per method with a finite PSNR
# against the full-resolution payload and against the reference, a speed-up, herzog's margins line, the noise
# floors and the per-region table.
# Usage: check_upsample_st.sh BUILD_DIR OUT_DIR
# shellcheck source=tests/pipelines/check_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/check_lib.sh"
SIZE=64x48 FRAMES=0-5 REFERENCE_SPP=2 METHODS="spatial temporal herzog herzog-favor-spatial taau spatial-demod" \
  bash "$here/pipelines/upsample-st.sh" "$build" "$out" "$here/assets/scenes/tower.glb" > "$out.log" 2>&1 ||
  fail "the pipeline failed" "$out.log"
summary="$out/summary.md"
[[ -f "$summary" ]] || fail "no summary.md" "$summary"
for m in spatial temporal herzog herzog-favor-spatial taau spatial-demod; do
  row="$(grep -E "^\| $m \|" "$summary" || true)"
  [[ -n "$row" ]] || fail "no row for $m" "$summary"
  # | method | shade | up | total | full | speed-up | PSNR | PSNR vs 2 spp |
  awk -F'|' -v m="$m" '{
      psnr = $8 + 0; ss = $9 + 0; speed = $7 + 0
      if (!(psnr > 10 && psnr < 100)) { print m ": PSNR " $8 " out of range"; exit 1 }
      if (!(ss > 10 && ss < 100)) { print m ": supersampled PSNR " $9 " out of range"; exit 1 }
      if (!(speed > 0)) { print m ": no speed-up"; exit 1 }
    }' <<< "$row" || fail "bad row: $row" "$summary"
done
grep -qE '^herzog - spatial: [+-][0-9.]+ dB, herzog - temporal: [+-][0-9.]+ dB\.$' "$summary" ||
  fail "no margins line" "$summary"
[[ -f "$out/tower/psnr.png" && -f "$out/tower/metrics.csv" ]] || fail "no per-frame chart or metrics" "$summary"
# Issue 24: each reference's noise floor above the scene's table (the payload's against 4 samples at the pixel
# centres, the 2-spp reference's against 8 spp), and the per-region table with its paired differences (6 frames
# are fewer than --static-frames 10: the static share is 0 %, the rows are there).
grep -qE '^Against the full-resolution payload: Noise floor: PSNR \(RGB\) of the 1-spp reference against a 4-spp render of its first 3 frames: [0-9.]+ \[' \
  "$summary" || fail "no noise-floor line for the payload" "$summary"
grep -qE '^Against the supersampled reference: Noise floor: PSNR \(RGB\) of the 2-spp reference against a 8-spp render of its first 3 frames: [0-9.]+ \[' \
  "$summary" || fail "no noise-floor line for the supersampled reference" "$summary"
grep -qE 'The best mean PSNR \(herzog(-favor-spatial)?, [0-9.]+ dB\) (is within 10 dB of it|is [0-9.]+ dB below it)' "$summary" ||
  fail "the noise-floor line does not compare the best score with the floor" "$summary"
for region in all static moving disoccluded; do
  grep -qE "^\| tower \| $region \| [0-9.]+ % \|" "$summary" || fail "no $region row in the region table" "$summary"
done
grep -qE '^\| tower \| moving \| [+-][0-9.]+ \[' "$summary" || fail "no per-region paired differences" "$summary"
echo "check_upsample_st.sh: ok"
