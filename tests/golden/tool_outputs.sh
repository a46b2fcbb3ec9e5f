#!/usr/bin/env bash
# Whole-tool regression check for refactors (not run by CTest: it takes a few minutes). Renders two built-in
# scenes at 128x96, runs every method of every tool on them, and writes every output under DIR (`record`),
# or runs the same commands again (into a temporary folder) and requires the pixels of every EXR (all parts, idiff -a, tolerance 0) and
# every metric of compare's CSV (timing columns dropped) to equal the recorded ones (`check`).
#
# Usage: tests/golden/tool_outputs.sh record|check DIR [BUILD_DIR]     (BUILD_DIR default: build/ci)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
mode="${1:?record|check}"
dir="${2:?DIR}"
build="${3:-$here/build/ci}"
case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
case "$dir" in /*) ;; *) dir="$PWD/$dir" ;; esac
bin="$build/apps"
out="$dir"
if [[ "$mode" == check ]]; then
  # A fresh folder per run: several checks may run at once on one machine.
  out="$(mktemp -d "${TMPDIR:-/tmp}/tool_outputs.XXXXXX")"
  trap 'rm -rf "$out"' EXIT
else
  rm -rf "$out"
  mkdir -p "$out"
fi

render() { "$bin/render-gbuffer/render-gbuffer" "$@" >/dev/null; }
up() { "$bin/upsample-st/upsample-st" "$@"; }
filt() { "$bin/filter-phlm/filter-phlm" "$@"; }
morph() { "$bin/morph-120hz/morph-120hz" "$@"; }
cmp() { "$bin/compare/compare" "$@" >/dev/null; }

for scene in walkers fan; do
  r="$out/$scene/render"
  render "$here/assets/scenes/$scene.glb" --out "$r" --size 128x96 --frames 0-11 --reference-spp 4
  u="$out/$scene/up"
  g="$r/gbuffer.####.exr"
  s="$r/shade.####.exr"
  up --gbuffer "$g" --input "$s" --out "$u/spatial.####.exr" --method spatial --debug-layers
  up --gbuffer "$g" --input "$s" --out "$u/temporal.####.exr" --method temporal --debug-layers
  up --gbuffer "$g" --input "$s" --out "$u/herzog.####.exr" --method herzog --debug-layers
  up --gbuffer "$g" --input "$s" --out "$u/herzog_fav_lag.####.exr" --method herzog --favor-spatial --lagged-wf
  up --gbuffer "$g" --input "$s" --out "$u/herzog_demod.####.exr" --method herzog --demodulate
  up --gbuffer "$g" --input "$s" --out "$u/herzog_ssao.####.exr" --method herzog --layer ssao --reset-frames 6
  up --gbuffer "$g" --input "$s" --out "$u/drobot.####.exr" --method drobot --debug-layers
  up --gbuffer "$g" --input "$s" --out "$u/drobot_refresh.####.exr" --method drobot --mode refresh
  f="$out/$scene/filter"
  for m in phlm taa ema fxaa; do
    filt --input "$r/color.####.exr" --gbuffer "$g" --out "$f/$m.####.exr" --method "$m" --debug-layers
  done
  filt --input "$r/color.####.exr" --gbuffer "$g" --out "$f/phlm_resumed.####.exr" --method phlm --frames 0-5 \
    --state-out "$f/state.exr"
  filt --input "$r/color.####.exr" --gbuffer "$g" --out "$f/phlm_resumed.####.exr" --method phlm --frames 6-11 \
    --state-in "$f/state.exr"
  m="$out/$scene/morph"
  for meth in didyk repeat blend warp; do
    morph --input "$r/color.####.exr" --gbuffer "$g" --out "$m/$meth.####.exr" --method "$meth" --frames 0-3 \
      --debug-layers
  done
  morph --input "$r/color.####.exr" --gbuffer "$g" --out "$m/perceived.####.exr" --perceive --frames 0-7
  c="$out/$scene/compare"
  cmp --reference "$r/reference.####.exr" "$u/spatial.####.exr" "$u/temporal.####.exr" "$u/herzog.####.exr" \
    "$u/drobot.####.exr" --gbuffer "$g" --csv "$c/up.csv" --error-maps "$c/maps"
  cmp --reference "$r/reference.####.exr" "$r/color.####.exr" "$f/phlm.####.exr" "$f/taa.####.exr" \
    "$f/ema.####.exr" "$f/fxaa.####.exr" --gbuffer "$g" --csv "$c/filter.csv"
  cmp --reference "$r/reference.####.exr" "$u/herzog_ssao.####.exr" --layer ssao --reference-layer ssao \
    --csv "$c/ssao.csv"
done

# Metric columns only: timing columns differ run to run.
strip_csv() {
  python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, h in enumerate(rows[0]) if not (h.endswith("_ms") or h.startswith("ms_") or h == "metrics_ms")]
def norm(x):  # 8 significant digits: compare wrote %.8g before it wrote round-trip digits
    try:
        return x if x in ("", "inf", "-inf") else "%.8g" % float(x)
    except ValueError:
        return x
for r in rows:
    print(",".join(norm(r[i]) for i in keep if i < len(r)))
PY
}

if [[ "$mode" == record ]]; then
  echo "tool_outputs.sh: recorded $(find "$out" -name '*.exr' | wc -l) EXR files in $out"
  exit 0
fi
fail=0
n=0
one_exr() {
  local rel="${1#"$2"/}"
  if [[ ! -f "$3/$rel" ]]; then echo "MISSING $rel"; return 0; fi
  idiff -a -fail 0 -warn 0 "$1" "$3/$rel" >/dev/null 2>&1 || echo "DIFFERS $rel"
}
export -f one_exr
n=$(find "$dir" -name '*.exr' | wc -l)
bad=$(find "$dir" -name '*.exr' | sort | xargs -P "$(nproc)" -I{} bash -c 'one_exr "$@"' _ {} "$dir" "$out")
if [[ -n "$bad" ]]; then echo "$bad"; fail=1; fi
while IFS= read -r f; do
  rel="${f#"$dir"/}"
  if ! diff <(strip_csv "$f") <(strip_csv "$out/$rel") >/dev/null; then echo "DIFFERS $rel"; fail=1; fi
done < <(find "$dir" -name '*.csv' ! -name timings.csv | sort)
echo "tool_outputs.sh: compared $n EXR files and the CSVs: $([[ $fail == 0 ]] && echo identical || echo DIFFERENCES)"
exit $fail
