#!/usr/bin/env bash
# herzog's ablation table (issues 15 and 16): which parts of seed 000's method carry its gain on the built-in
# scenes. Runs pipelines/upsample-st.sh with the two baselines, herzog as published (this project's defaults) and
# one variant per switched-off or changed part, each an upsample-st option recorded in the output headers
# (temporal:methodParameters):
#   herzog-fixed-wf-1       --fixed-wf 1                 no gradient adaptation: w_f = 1 everywhere (eq. 5's
#                                                        accumulation with the kernel at its cap; misses still restart)
#   herzog-fixed-wf-0.5     --fixed-wf 0.5               no adaptation, a middle constant
#   herzog-no-temporal      --gradient-filter none       no temporal filter of the gradient (|g_t| alone)
#   herzog-no-lowpass       --gradient-mip-level 1       no spatial low-pass: the gradient at its own full/2 level
#   herzog-flat             --fallback flat              the literal eq. 3 box at gamma w_f = 0 (before issue 15)
#   herzog-a0.7             --a 0.7                      the paper's elephant setting of eq. 8
#   herzog-cap8             --kernel-gamma 8 --max-kernel-gamma 8   the kernel cap raised past the paper's 4
#   herzog-raster           (payload rendered in raster pattern order, render-gbuffer --shade-jitter regular-raster)
# and prints the paired differences variant - herzog with their 95% intervals (compare's).
#
# Usage: pipelines/upsample-st-ablation.sh [BUILD_DIR=build/release] [OUT_DIR=report/upsample-st-ablation]
#        [SCENE.glb ...]
# Environment: upsample-st.sh's SIZE, FRAMES, FPS, FACTOR, RENDER_ARGS, NOISE_AVERAGED_SPP, RENDERS, REUSE_RENDER;
#   METHODS (default "spatial temporal herzog"; add e.g. drobot taau for the full table), EXTRA_VARIANTS (more
#   lines "NAME herzog OPTIONS").
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
use_build "${1:-}"
OUT="${2:-report/upsample-st-ablation}"
shift $(( $# > 2 ? 2 : $# ))
export METHODS="${METHODS:-spatial temporal herzog}"
export VARIANTS="herzog-fixed-wf-1 herzog --fixed-wf 1
herzog-fixed-wf-0.5 herzog --fixed-wf 0.5
herzog-no-temporal herzog --gradient-filter none
herzog-no-lowpass herzog --gradient-mip-level 1
herzog-flat herzog --fallback flat
herzog-a0.7 herzog --a 0.7
herzog-cap8 herzog --kernel-gamma 8 --max-kernel-gamma 8
herzog-raster herzog
${EXTRA_VARIANTS:-}"
pairs="herzog:spatial,herzog:temporal"
while read -r n _; do
  [[ -n "$n" ]] && pairs+=",$n:herzog"
done <<< "$VARIANTS"
export PAIRS="$pairs"
exec bash "$ROOT/pipelines/upsample-st.sh" "$BUILD" "$OUT" "$@"
