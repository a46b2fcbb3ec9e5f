#!/usr/bin/env bash
# Smoke test of pipelines/filter-phlm-tune.sh's per-region output (issue 24): one tiny tuning sequence (walkers,
# static camera, 64x48, frames 0-5), TAA at two alphas and EMA at two, compare with --regions motion
# --static-frames 2. Checks tuning-regions.csv (a row per run and region; the shares of static, moving and
# disoccluded sum to 1 per run; the `all` row's PSNR equals tuning.csv's), the per-region section of tuning.md with
# the optimum per region, and tuned-variants.txt (the static and moving optimum as filter-phlm.sh VARIANTS lines,
# consistent with the CSV's highest mean), and that APPEND=1 keeps the optimum over every run so far.
# Usage: check_filter_phlm_tune.sh BUILD_DIR OUT_DIR
# shellcheck source=tests/pipelines/check_lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/../pipelines/check_lib.sh"
SIZE=64x48 TUNE_SET="walkers-tiny walkers.glb 0-5 --seed 7" TAA_ALPHAS="0.2 1" TAA_CLIPS=variance EMA_ALPHAS="0.5 0.9" \
  FXAA_SUBPIX="" PHLM_LAMBDAS="" STATIC_FRAMES=2 \
  bash "$here/pipelines/filter-phlm-tune.sh" "$build" "$out/tune" > "$out/tune.log" 2>&1 ||
  fail "filter-phlm-tune.sh failed" "$out/tune.log"
csv="$out/tune/tuning-regions.csv"
[[ -f "$csv" ]] || fail "no tuning-regions.csv" "$out/tune.log"
python3 - "$csv" "$out/tune/tuning.csv" "$out/tune/tuned-variants.txt" <<'PY' || fail "tuning-regions.csv / tuned-variants.txt inconsistent" "$csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
runs = {(r["method"], r["setting"]) for r in rows}
assert runs == {("taa", "clip=variance/alpha=0.2"), ("taa", "clip=variance/alpha=1"), ("ema", "alpha=0.5"),
                ("ema", "alpha=0.9")}, runs
whole = {(r["method"], r["setting"]): float(r["psnr_rgb_db"]) for r in csv.DictReader(open(sys.argv[2]))}
best = {}
for run in runs:
    by = {r["region"]: r for r in rows if (r["method"], r["setting"]) == run}
    assert set(by) == {"all", "static", "moving", "disoccluded"}, by.keys()
    shares = sum(float(by[g]["share"]) for g in ("static", "moving", "disoccluded"))
    assert abs(shares - 1.0) < 1e-6, shares
    assert float(by["static"]["share"]) > 0.0, "no static pixels on a static camera"
    assert abs(float(by["all"]["psnr_rgb_db"]) - whole[run]) < 1e-9, (by["all"], whole[run])
    for g in ("static", "moving"):
        v = float(by[g]["psnr_rgb_db"])
        if run[0] not in best or g not in best[run[0]] or v > best[run[0]][g][1]:
            best.setdefault(run[0], {})[g] = (run[1], v)
lines = open(sys.argv[3]).read().split("\n")
for method, by_region in best.items():
    for g, (setting, _) in by_region.items():
        value = setting.split("alpha=")[1]
        args = f"--taa-clip variance --taa-alpha {value}" if method == "taa" else f"--ema-alpha {value}"
        want = f"{method}-tuned-{g} {method} {args}"
        assert want in lines, (want, lines)
PY
grep -qE '^Optimum of taa per region: whole frame: \*\*clip=variance/alpha=(0.2|1)\*\* \([0-9.]+ dB\); static: ' \
  "$out/tune/tuning.md" || fail "no per-region optimum in tuning.md" "$out/tune/tuning.md"
grep -qE '^\| clip=variance/alpha=0.2 \| [0-9.]+ \| [0-9.]+ \| [0-9.]+ \| ' "$out/tune/tuning.md" ||
  fail "no per-region row in tuning.md" "$out/tune/tuning.md"
# APPEND=1 extends the grid (here EMA at 0.7, the render reused): the optimum is taken over every run so far, so
# tuned-variants.txt keeps TAA's lines although this invocation ran no TAA.
SIZE=64x48 TUNE_SET="walkers-tiny walkers.glb 0-5 --seed 7" TAA_ALPHAS="" EMA_ALPHAS="0.7" FXAA_SUBPIX="" \
  PHLM_LAMBDAS="" STATIC_FRAMES=2 APPEND=1 REUSE_RENDER=1 \
  bash "$here/pipelines/filter-phlm-tune.sh" "$build" "$out/tune" > "$out/tune-append.log" 2>&1 ||
  fail "filter-phlm-tune.sh APPEND=1 failed" "$out/tune-append.log"
grep -q "reusing" "$out/tune-append.log" || fail "APPEND=1 REUSE_RENDER=1 rendered again" "$out/tune-append.log"
[[ "$(grep -c ',walkers-tiny,' "$csv")" == 20 ]] || fail "tuning-regions.csv does not have 5 runs x 4 regions" "$csv"
grep -qE '^taa-tuned-static taa --taa-clip variance --taa-alpha (0.2|1)$' "$out/tune/tuned-variants.txt" ||
  fail "APPEND=1 lost TAA's optimum" "$out/tune/tuned-variants.txt"
grep -qE '^ema-tuned-static ema --ema-alpha (0.5|0.7|0.9)$' "$out/tune/tuned-variants.txt" ||
  fail "no EMA static optimum after APPEND=1" "$out/tune/tuned-variants.txt"
echo "check_filter_phlm_tune.sh: ok"
