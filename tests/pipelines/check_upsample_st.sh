#!/usr/bin/env bash
# Runs pipelines/upsample-st.sh on a tiny render of the built-in tower scene (64x48, 6 frames, every payload
# term, a 2-spp supersampled reference) and checks its summary: one table row per method with a finite PSNR
# against the full-resolution payload and against the reference, a speed-up, and herzog's margins line.
# Usage: check_upsample_st.sh BUILD_DIR OUT_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$1"
out="$2"
rm -rf "$out"
SIZE=64x48 FRAMES=0-5 REFERENCE_SPP=2 METHODS="spatial temporal herzog herzog-favor-spatial taau spatial-demod" \
  bash "$here/pipelines/upsample-st.sh" "$build" "$out" "$here/assets/scenes/tower.glb" > "$out.log" 2>&1 || {
  cat "$out.log"
  echo "check_upsample_st.sh: the pipeline failed" >&2
  exit 1
}
summary="$out/summary.md"
fail() { cat "$summary" >&2; echo "check_upsample_st.sh: $*" >&2; exit 1; }
[[ -f "$summary" ]] || fail "no summary.md"
for m in spatial temporal herzog herzog-favor-spatial taau spatial-demod; do
  row="$(grep -E "^\| $m \|" "$summary" || true)"
  [[ -n "$row" ]] || fail "no row for $m"
  # | method | shade | up | total | full | speed-up | PSNR | PSNR vs 2 spp |
  awk -F'|' -v m="$m" '{
      psnr = $8 + 0; ss = $9 + 0; speed = $7 + 0
      if (!(psnr > 10 && psnr < 100)) { print m ": PSNR " $8 " out of range"; exit 1 }
      if (!(ss > 10 && ss < 100)) { print m ": supersampled PSNR " $9 " out of range"; exit 1 }
      if (!(speed > 0)) { print m ": no speed-up"; exit 1 }
    }' <<< "$row" || fail "bad row: $row"
done
grep -qE '^herzog - spatial: [+-][0-9.]+ dB, herzog - temporal: [+-][0-9.]+ dB\.$' "$summary" || fail "no margins line"
[[ -f "$out/tower/psnr.png" && -f "$out/tower/metrics.csv" ]] || fail "no per-frame chart or metrics"
echo "check_upsample_st.sh: ok"
