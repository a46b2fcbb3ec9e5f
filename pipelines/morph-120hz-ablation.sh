#!/usr/bin/env bash
# didyk's ablation table (issue 16): which parts of seed 004's method carry its gain. Runs
# pipelines/morph-120hz.sh with didyk as published, the `repeat` and `warp` baselines, and one variant per
# switched-off part, each a morph-120hz option recorded in the output headers:
#   didyk-nosnap    --no-snap                                  the grid stays regular (no snapping to motion edges)
#   didyk-noblur    --distortion-low 50 --distortion-high 100  no selective blur of the in-between frames
#   didyk-nocomp    --no-compensation                          no high-frequency compensation of the rendered frame
#   didyk-grid2     --grid 2                                   the finest grid (2 px cells): towards a per-pixel warp
#   warp            (a method)                                 the per-pixel splat instead of the grid, with neither
#                                                              blur nor compensation (their input is the grid's
#                                                              distortion)
# The paired differences (paired.csv, and the summary's table) give each variant - didyk with its 95% interval.
#
# Usage: pipelines/morph-120hz-ablation.sh [BUILD_DIR=build/release] [OUT_DIR=report/morph-120hz-ablation]
#        [SCENE.glb ...]
# Environment: morph-120hz.sh's SIZE, FRAMES, REPEAT (default 1 here: the timings are not the point).
# shellcheck source=pipelines/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
use_build "${1:-}"
OUT="${2:-report/morph-120hz-ablation}"
shift $(( $# > 2 ? 2 : $# ))
export METHODS="didyk repeat warp"
export VARIANTS="didyk-nosnap didyk --no-snap
didyk-noblur didyk --distortion-low 50 --distortion-high 100
didyk-nocomp didyk --no-compensation
didyk-grid2 didyk --grid 2"
export FFMPEG=0
export REPEAT="${REPEAT:-1}"
exec bash "$ROOT/pipelines/morph-120hz.sh" "$BUILD" "$OUT" "$@"
