#!/usr/bin/env bash
# PHLM's ablation table (issue 16): which parts of seed 003's method carry its gain on the built-in scenes. Runs
# pipelines/filter-phlm.sh on the renders of the Table 2 run (rendering them first when they are missing) with PHLM
# and one variant per switched-off part, each a filter-phlm option recorded in the output headers
# (temporal:methodParameters):
#   phlm-no-feature    --no-feature            intercept-only RLS: a per-pixel running mean with the same resets
#   phlm-nearest       --model-fetch nearest   the nearest pixel's model instead of the bilinear fetch
#   phlm-no-box        --no-box-test           no box test (Algorithm 1 lines 13-19) and none of its resets
#   phlm-eq1           --feature-alpha eq1     the literal eq. 1 reading of the feature's alpha (history weight)
#   phlm-mean-no-box   --no-feature --no-box-test   the running mean alone (what the box test adds to it)
#   phlm-phi-linear    --feature-phi linear    the feature's weight linear in l, phi = (a + b v) l (UE4's
#                      HistoryFactor) instead of section 5.1's printed a l^2 + b v l^3 (issue 24; docs "The feature's
#                      weight")
#   phlm-catmull-rom   --model-fetch catmull-rom    not an ablation: the sharper fetch of docs "Edges"
# and prints the paired differences variant - phlm with their 95% intervals (compare's, when it has them).
#
# Usage: pipelines/filter-phlm-ablation.sh [BUILD_DIR=build/release] [OUT_DIR=report/filter-phlm-ablation]
#        [SCENE.glb ...]
# Environment: RENDERS (folder of the Table 2 renders, default report/filter-phlm), and filter-phlm.sh's SIZE,
#   FRAMES, FPS, RENDER_ARGS, WARMUP (the renders must match them).
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
use_build "${1:-}"
OUT="${2:-report/filter-phlm-ablation}"
shift $(( $# > 2 ? 2 : $# ))
export RENDERS="${RENDERS:-report/filter-phlm}"
export REUSE_RENDER=1
export METHODS="phlm"
export VARIANTS="phlm-no-feature phlm --no-feature
phlm-nearest phlm --model-fetch nearest
phlm-no-box phlm --no-box-test
phlm-eq1 phlm --feature-alpha eq1
phlm-mean-no-box phlm --no-feature --no-box-test
phlm-phi-linear phlm --feature-phi linear
phlm-catmull-rom phlm --model-fetch catmull-rom"
export PAIRS="phlm-no-feature:phlm,phlm-nearest:phlm,phlm-no-box:phlm,phlm-eq1:phlm,phlm-mean-no-box:phlm,phlm-phi-linear:phlm,phlm-catmull-rom:phlm,phlm:input"
exec bash "$ROOT/pipelines/filter-phlm.sh" "$BUILD" "$OUT" "$@"
