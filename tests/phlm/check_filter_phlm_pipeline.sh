#!/usr/bin/env bash
# Smoke test of pipelines/filter-phlm.sh and pipelines/filter-phlm-ablation.sh: a tiny render of the built-in fence
# scene (64x48, 6 frames, 2-spp reference), every method and the default variants, then the ablation on the same
# render. Checks the Table 2 summary (a row per scene with a finite PSNR for every sequence, the mean row, the
# paired-difference table, the noise floor, the region table and its paired differences) and the ablation's paired
# table; issue 24: the list of the runs' arguments and the ablation's phlm-phi-linear row.
# Usage: check_filter_phlm_pipeline.sh BUILD_DIR OUT_DIR
# shellcheck source=tests/pipelines/check_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/../pipelines/check_lib.sh"
SIZE=64x48 FRAMES=0-5 WARMUP=2 REFERENCE_SPP=2 RENDER_ARGS="--payload direct,shadow" \
  bash "$here/pipelines/filter-phlm.sh" "$build" "$out/table2" "$here/assets/scenes/fence.glb" > "$out/table2.log" 2>&1 ||
  fail "filter-phlm.sh failed" "$out/table2.log"
summary="$out/table2/summary.md"
[[ -f "$summary" ]] || fail "no summary.md" "$out/table2.log"
header="$(grep -E '^\| scene \| input \| phlm \| taa \| ema \| fxaa \| taa-0.1 \| taa-2014 \| ema-tuned-static \|$' "$summary" || true)"
[[ -n "$header" ]] || fail "no Table 2 header with every sequence" "$summary"
# Issue 24: which baseline each column is (every run's filter-phlm arguments).
grep -qF -- '- `taa-0.1`: `--method taa --taa-alpha 0.1`' "$summary" || fail "no list of the runs' arguments" "$summary"
row="$(grep -E '^\| fence \|' "$summary" | head -1)"
# Every cell starts with a PSNR between 5 and 100 dB.
awk -F'|' '{ for (i = 3; i < NF; ++i) { v = $i + 0; if (!(v > 5 && v < 100)) { print "cell " i ": " $i; exit 1 } } }' \
  <<< "$row" || fail "bad Table 2 row: $row" "$summary"
grep -qE '^\| mean of the scenes \|' "$summary" || fail "no mean row" "$summary"
grep -qE '^\| scene \| phlm - taa: PSNR dB / flicker \|' "$summary" || fail "no paired-difference table" "$summary"
[[ -f "$out/table2/fence/psnr.png" && -f "$out/table2/fence/metrics.json" ]] || fail "no chart or JSON"
# Issue 24: the reference's noise floor above the scene's table, and the per-region table and paired differences
# (6 frames are fewer than --static-frames 10: the static share is 0 %, the rows are there).
grep -qE '^Noise floor: PSNR \(RGB\) of the 2-spp reference against a 8-spp render of its first 3 frames: [0-9.]+ ' \
  "$summary" || fail "no noise-floor line" "$summary"
for region in all static moving disoccluded; do
  grep -qE "^\| fence \| $region \| [0-9.]+ % \|" "$summary" || fail "no $region row in the region table" "$summary"
done
grep -qE '^\| fence \| disoccluded \| [+-][0-9.]+ \[' "$summary" || fail "no per-region paired differences" "$summary"
# The ablation reuses the render.
SIZE=64x48 FRAMES=0-5 WARMUP=2 RENDERS="$out/table2" \
  bash "$here/pipelines/filter-phlm-ablation.sh" "$build" "$out/ablation" "$here/assets/scenes/fence.glb" \
  > "$out/ablation.log" 2>&1 || fail "filter-phlm-ablation.sh failed" "$out/ablation.log"
grep -q "reusing" "$out/ablation.log" || fail "the ablation rendered again" "$out/ablation.log"
grep -qE '^\| scene \| phlm-no-feature - phlm: PSNR dB / flicker \|' "$out/ablation/summary.md" ||
  fail "no ablation table" "$out/ablation/summary.md"
# Issue 24: the linear feature weight's row (--feature-phi linear) beside the paper's form.
grep -qE '\| phlm-phi-linear - phlm: PSNR dB / flicker \|' "$out/ablation/summary.md" ||
  fail "no phlm-phi-linear column in the ablation table" "$out/ablation/summary.md"
grep -qa -- "--feature-phi=linear" "$out/ablation/fence/phlm-phi-linear/phlm-phi-linear.0003.exr" ||
  fail "temporal:methodParameters does not record --feature-phi linear"
# The variant is recorded in the output header.
grep -qa -- "--no-feature=on" "$out/ablation/fence/phlm-no-feature/phlm-no-feature.0003.exr" ||
  fail "temporal:methodParameters does not record --no-feature"
echo "check_filter_phlm_pipeline.sh: ok"
