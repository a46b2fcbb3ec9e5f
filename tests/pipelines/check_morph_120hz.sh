#!/usr/bin/env bash
# Runs pipelines/morph-120hz.sh on a tiny render of the built-in fan scene (64x48, 3 frames at 40 Hz -> 9 at 120 Hz,
# one timed run, no ffmpeg) and checks its summary (issue 24): a table row per method with a finite in-between PSNR
# (compare --frames 3-8y3 leaves the rendered frames out, so no mean is inf), the reference's noise-floor line (the
# native 120 Hz render against 4 samples at its pixel centres), and the per-region table (all / static / moving /
# disoccluded, shares summing to 100 %) with didyk's paired differences per region.
# Usage: check_morph_120hz.sh BUILD_DIR OUT_DIR
# shellcheck source=tests/pipelines/check_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/check_lib.sh"
SIZE=64x48 FRAMES=3 REPEAT=1 FFMPEG=0 \
  bash "$here/pipelines/morph-120hz.sh" "$build" "$out" "$here/assets/scenes/fan.glb" > "$out.log" 2>&1 ||
  fail "the pipeline failed" "$out.log"
summary="$out/summary.md"
[[ -f "$summary" ]] || fail "no summary.md" "$summary"
for m in didyk repeat blend warp; do
  row="$(grep -E "^\| fan \| $m \|" "$summary" | head -1 || true)"
  [[ -n "$row" ]] || fail "no row for $m" "$summary"
  # | scene | method | L | in-between [ci] | ...: a finite in-between mean between 5 and 100 dB.
  awk -F'|' -v m="$m" '{ v = $5 + 0; if ($5 ~ /inf/ || !(v > 5 && v < 100)) { print m ": in-between " $5; exit 1 } }' \
    <<< "$row" || fail "bad row: $row" "$summary"
done
grep -qE '^- fan: Noise floor: PSNR \(RGB\) of the 1-spp reference against a 4-spp render of its first 3 frames: [0-9.]+ \[' \
  "$summary" || fail "no noise-floor line" "$summary"
grep -qE 'The best mean PSNR \([a-z]+, [0-9.]+ dB\) (is within 10 dB of it|is [0-9.]+ dB below it)' "$summary" ||
  fail "the noise-floor line does not compare the best score with the floor" "$summary"
total=0
for region in all static moving disoccluded; do
  row="$(grep -E "^\| fan \| $region \| [0-9.]+ % \|" "$summary" || true)"
  [[ -n "$row" ]] || fail "no $region row in the region table" "$summary"
  [[ "$region" == all ]] || total="$(awk -F'|' -v t="$total" '{ print t + $4 }' <<< "$row")"
done
awk -v t="$total" 'BEGIN { exit !(t > 99.8 && t < 100.2) }' ||
  fail "region shares sum to $total %, not 100 %" "$summary"
grep -qE '^\| fan \| moving \| [+-][0-9.]+ \[' "$summary" || fail "no per-region paired differences" "$summary"
grep -qE '^\| scene \| region \| didyk - repeat \| didyk - blend \| didyk - warp \|$' "$summary" ||
  fail "the per-region paired differences are not didyk against repeat, blend and warp" "$summary"
# The lag column: the mean of the perceived frames' temporal:lagMs headers (one iinfo over all of them), a number
# for every method; repeat holds each frame for the whole 40 Hz interval, so it lags.
csv="$out/summary.csv"
col="$(head -1 "$csv" | tr ',' '\n' | grep -nx lag_ms | cut -d: -f1)"
[[ -n "$col" ]] || fail "summary.csv has no lag_ms column" "$summary"
for m in didyk repeat blend warp; do
  lag="$(awk -F, -v m="$m" -v c="$col" '$2 == m { print $c }' "$csv")"
  [[ "$lag" =~ ^-?[0-9]+(\.[0-9]+)?$ ]] || fail "$m: lag_ms is '$lag', not a number" "$summary"
done
awk -F, -v c="$col" '$2 == "repeat" { exit !($c > 1) }' "$csv" || fail "repeat's lag is not above 1 ms" "$summary"
echo "check_morph_120hz.sh: ok"
