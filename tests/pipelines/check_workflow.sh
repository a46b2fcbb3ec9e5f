#!/usr/bin/env bash
# Runs the Snakemake workflow (pipelines/workflow) with config/default.yaml's three experiments shrunk to one scene
# each at 64x48 (six frames; morph 3 at 40 Hz -> 9 at 120 Hz) and checks each summary for the reference's noise
# floor line (issue 24: filter-phlm's 2-spp reference against 8 spp; upsample-st's and morph-120hz's one sample at
# the pixel centres against 4 there) and the per-region table. Exit 77 (skipped) without snakemake.
# Usage: check_workflow.sh BUILD_DIR OUT_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$1"
out="$2"
command -v snakemake > /dev/null 2>&1 || { echo "check_workflow.sh: snakemake not installed: skipped"; exit 77; }
rm -rf "$out"
mkdir -p "$out"
python3 - "$here/pipelines/workflow/config/default.yaml" "$out/config.yaml" <<'PY'
import sys
s = open(sys.argv[1]).read()
for a, b in (("size: 160x128, fps: 30, frames: 0-23, chunk: 12", "size: 64x48, fps: 30, frames: 0-5, chunk: 3"),
             ("size: 128x72, fps: 40, frames: 0-23, chunk: 12", "size: 64x48, fps: 40, frames: 0-5, chunk: 3"),
             ("size: 128x128, fps: 40, frames: 0-7, chunk: 8", "size: 64x48, fps: 40, frames: 0-2, chunk: 3"),
             ("size: 128x128, fps: 120, frames: 0-23, chunk: 12", "size: 64x48, fps: 120, frames: 0-8, chunk: 9"),
             ("frames: 0-23\n", "frames: 0-5\n"), ("frames: 0-7\n", "frames: 0-2\n"),
             ("scenes: [fence, tower, fan, walkers]", "scenes: [fence]"), ("scenes: [walkers, tower, fan]", "scenes: [tower]"),
             ("scenes: [fan, tower]", "scenes: [fan]"), ("reference-spp 16", "reference-spp 2")):
    if a not in s:
        sys.exit(f"check_workflow.sh: config/default.yaml has no '{a.strip()}': update the test's shrinking")
    s = s.replace(a, b)
open(sys.argv[2], "w").write(s)
PY
# Run from OUT_DIR: snakemake keeps its .snakemake folder (and lock) in the working folder, so this test does not
# lock the checkout against another workflow run (the Snakefile resolves config paths from the repository root).
(cd "$out" && snakemake -s "$here/pipelines/workflow/Snakefile" --cores 2 --configfile "$out/config.yaml" \
  --config build="$build" out="$out/out" -q) > "$out/snakemake.log" 2>&1 || {
  cat "$out/snakemake.log"
  echo "check_workflow.sh: the workflow failed" >&2
  exit 1
}
fail() { cat "$2" >&2; echo "check_workflow.sh: $1" >&2; exit 1; }
check() {  # EXPERIMENT SCENE SPP SPP4
  local summary="$out/out/$1/summary.md"
  [[ -f "$summary" ]] || fail "no $1 summary" "$out/snakemake.log"
  grep -qE "^Noise floor: PSNR \(RGB\) of the $3-spp reference against a $4-spp render of its first 3 frames: (inf|[0-9.]+) \[" \
    "$summary" || fail "$1: no noise-floor line" "$summary"
  for region in static moving disoccluded; do
    grep -qE "^\| $region \| [0-9.]+ % \|" "$summary" || fail "$1: no $region row" "$summary"
  done
}
check filter-phlm fence 2 8
check upsample-st tower 1 4
check morph-120hz fan 1 4
# The payload of the morph experiment (direct, shadow) has no noise at the pixel centres: its floor is inf, and a
# finite best score is not compared with it.
grep -qE '^Noise floor: .*: inf \[inf, inf\] dB' "$out/out/morph-120hz/summary.md" ||
  fail "morph-120hz: the noiseless payload's floor is not inf" "$out/out/morph-120hz/summary.md"
echo "check_workflow.sh: ok"
