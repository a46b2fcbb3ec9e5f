#!/usr/bin/env bash
# compare_emulated.sh MODEL LEVEL COMPARE WORKDIR: the tool itself on an emulated CPU (run_emulated.sh): writes a
# 3-frame 64x48 reference and test sequence with oiiotool (on the host), then runs `compare --verbose --flip ldr`
# on the emulated MODEL; it must succeed, say `compare: CPU kernels: LEVEL`, and its PSNR, SSIM and FLIP means must
# agree with the same run on the host (at the host's level) within 1e-4: the kernel copies differ in FMA
# contraction only (docs/building.md, "CPU targets"). This runs the tool's own code (apps/, the comparison engine,
# EXR reading) besides the kernels the unit tests run.
set -euo pipefail
[ $# -eq 4 ] || { echo "usage: compare_emulated.sh MODEL LEVEL COMPARE WORKDIR" >&2; exit 2; }
model=$1 level=$2 compare=$3 dir=$4
here=$(cd "$(dirname "$0")" && pwd)
command -v oiiotool >/dev/null ||
  { echo "compare_emulated.sh: SKIP: oiiotool not found (Debian's openimageio-tools)" >&2; exit 77; }
rm -rf "$dir" && mkdir -p "$dir"
for i in 0 1 2; do
  oiiotool --pattern checker:width=8:height=8 64x48 3 -o "$dir/ref.000$i.exr"
  oiiotool --pattern noise:type=uniform:min=0:max=1:seed=$i 64x48 3 -o "$dir/test.000$i.exr"
done
set +e
"$here/run_emulated.sh" "$model" "$level" "$compare" --verbose --reference "$dir/ref.####.exr" \
  "$dir/test.####.exr" --flip ldr --json "$dir/summary.json" >"$dir/log.txt" 2>&1
rc=$?
set -e
cat "$dir/log.txt"
[ $rc -ne 77 ] || exit 77
[ $rc -eq 0 ] || { echo "compare_emulated.sh: compare exited $rc on the emulated $model" >&2; exit 1; }
grep -q "^compare: CPU kernels: $level " "$dir/log.txt" ||
  { echo "compare_emulated.sh: compare did not choose $level on the emulated $model (log above)" >&2; exit 1; }
env -u TEMPORAL_ISA "$compare" --reference "$dir/ref.####.exr" "$dir/test.####.exr" --flip ldr \
  --json "$dir/host.json" >/dev/null
python3 - "$dir/summary.json" "$dir/host.json" <<'PY'
import json, sys
emulated, host = (json.load(open(p))["sequences"][0] for p in sys.argv[1:])
bad = [f"{m}: {emulated[m]['mean']!r} emulated, {host[m]['mean']!r} on the host"
       for m in ("psnr_rgb", "ssim", "flip") if abs(emulated[m]["mean"] - host[m]["mean"]) > 1e-4]
if bad: sys.exit("compare_emulated.sh: the emulated run disagrees with the host's: " + "; ".join(bad))
PY
echo "compare_emulated.sh: compare ran at $level on the emulated $model"
