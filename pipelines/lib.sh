# shellcheck shell=bash
# pipelines/lib.sh: the preamble every script of pipelines/ sources (docs/pipelines.md, "lib.sh"):
#
#   source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
#   use_build "${1:-}"                          # BUILD: absolute build folder
#   require_tools render-gbuffer filter-phlm compare
#   filter="$(tool_path filter-phlm)"
#   METHODS="${METHODS:-$(methods_of filter-phlm)}"
#
# It turns on strict mode (set -euo pipefail) in the sourcing script and sets ROOT (the repository root) and
# PIPELINE (the sourcing script's file name, for messages). Method lists come from the tools' registries
# (pipelines/workflow/scripts/methods.py, shared with the Snakefile), never from a list written here.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PIPELINE="$(basename "${BASH_SOURCE[1]:-$0}")"
# The one table formatter (pipelines/tables.py) and the registry helper, for the sourcing scripts.
# shellcheck disable=SC2034
TABLES="$ROOT/pipelines/tables.py"
METHODS_PY="$ROOT/pipelines/workflow/scripts/methods.py"

# Messages on stderr, prefixed with the script's name; die exits with CODE (default 2: a setup error, as every
# script exited before).
say() { echo "$PIPELINE: $*" >&2; }
die() {
  echo "$PIPELINE: $1" >&2
  exit "${2:-2}"
}

# use_build DIR: sets BUILD, the build folder holding apps/<tool>/<tool>: DIR (the script's BUILD_DIR argument),
# else the BUILD environment variable, else build/release. A relative folder is taken from the current folder
# when it exists there, else from the repository root (so a script works from any folder).
use_build() {
  BUILD="${1:-${BUILD:-build/release}}"
  case "$BUILD" in
    /*) ;;
    *) if [[ -d "$PWD/$BUILD" ]]; then BUILD="$PWD/$BUILD"; else BUILD="$ROOT/$BUILD"; fi ;;
  esac
}

# tool_path NAME: the built tool (a suite tool under apps/, or a path relative to BUILD such as
# tests/benchmarks/phlm/phlm_edge_split).
tool_path() {
  case "$1" in
    */*) echo "$BUILD/$1" ;;
    *) echo "$BUILD/apps/$1/$1" ;;
  esac
}

# How to build a missing target: the preset named by BUILD's folder when BUILD is build/<preset>.
build_hint() {
  local target="${1##*/}" preset
  preset="$(basename "$BUILD")"
  if [[ "$BUILD" == "$ROOT/build/$preset" && -n "$(sed -n "/\"name\": \"$preset\"/p" "$ROOT/CMakePresets.json" 2>/dev/null)" ]]; then
    echo "cmake --preset $preset && cmake --build --preset $preset --target $target"
  else
    echo "cmake -S $ROOT -B $BUILD && cmake --build $BUILD --target $target"
  fi
}

# require_tools NAME...: each tool exists and is executable, else exit 2 saying how to build it.
require_tools() {
  local t p
  for t in "$@"; do
    p="$(tool_path "$t")"
    [[ -x "$p" ]] || die "$p is missing: build it first ($(build_hint "$t"))"
  done
}

# methods_of TOOL: the tool's methods, space-separated, from its registry (--list-methods-json, read by
# methods.py). Named variants are not methods: method_args resolves them.
methods_of() {
  local out
  out="$(python3 "$METHODS_PY" names "$(tool_path "$1")")" || die "cannot read the methods of $1"
  paste -sd ' ' <<< "$out"
}

# method_args TOOL NAME: the arguments that run NAME (a method, a named variant such as herzog-favor-spatial,
# either with a name suffix such as -demod), from the tool's registry. Fails (status 2) on an unknown name.
method_args() {
  local out
  out="$(python3 "$METHODS_PY" args "$(tool_path "$1")" "$2")" || return 2
  echo "${out#*$'\t'}"
}

# add_runs TOOL ARRAY: appends to the array named ARRAY one "NAME ARGUMENTS" per run: each name of METHODS under
# its own name with the arguments the tool's registry gives it (method_args; exit 2 on an unknown name), then the
# VARIANTS lines (add_variant_runs).
add_runs() {
  local -n runs_ref="$2"
  local m args
  for m in $METHODS; do
    args="$(method_args "$1" "$m")" || die "unknown method '$m' in METHODS ($1 --list-methods lists the names)"
    runs_ref+=("$m $args")
  done
  add_variant_runs "$2" <<< "${VARIANTS:-}"
}

# add_variant_runs ARRAY: appends each line "NAME METHOD OPTIONS" of stdin (a VARIANTS or TUNED line) to the array
# named ARRAY as "NAME --method METHOD OPTIONS"; empty lines are skipped.
add_variant_runs() {
  local -n variants_ref="$1"
  local n m args
  while read -r n m args; do
    [[ -n "$n" ]] && variants_ref+=("$n --method $m $args")
  done
  return 0
}

# use_scenes "NAME..." SCENE...: sets the array `scenes` to the SCENE arguments, else to the built-in scenes
# assets/scenes/NAME.glb that exist; exits 2 when that leaves none.
use_scenes() {
  local defaults="$1" s
  shift
  scenes=("$@")
  if [[ ${#scenes[@]} -eq 0 ]]; then
    for s in $defaults; do
      if [[ -f "$ROOT/assets/scenes/$s.glb" ]]; then scenes+=("$ROOT/assets/scenes/$s.glb"); fi
    done
  fi
  [[ ${#scenes[@]} -gt 0 ]] || die "no scenes given and none in $ROOT/assets/scenes"
}

# render_or_reuse LABEL DIR WHAT SCENE RENDER_ARG...: `render-gbuffer SCENE --out DIR RENDER_ARG...`, announced on
# stderr as "== LABEL: rendering WHAT"; when REUSE_RENDER=1 and DIR exists, DIR is kept instead ("== LABEL:
# reusing DIR").
render_or_reuse() {
  local label="$1" dir="$2" what="$3" scene="$4"
  shift 4
  if [[ "${REUSE_RENDER:-0}" == 1 && -d "$dir" ]]; then
    echo "== $label: reusing $dir" >&2
    return 0
  fi
  echo "== $label: rendering $what" >&2
  "$(tool_path render-gbuffer)" "$scene" --out "$dir" "$@"
}

# code_block FILE: FILE's text as a Markdown code block (a table compare printed), then an empty line.
code_block() {
  echo '```'
  cat "$1"
  echo '```'
  echo
}

# The reference's noise floor (issue 24; docs/pipelines.md, "Noise floor"): a pipeline renders the first few frames
# of its reference again at 4x the samples and compare scores the reference against that render; tables.py
# noise-floor prints the PSNR above the pipeline's table and says when the best score comes within 10 dB of it
# (then the table cannot rank methods finer than the reference's own noise).
#
# floor_frames FRAMES COUNT: the first COUNT frames of the range FRAMES ("A-B", "A-BxN", ...), as "A-(A+COUNT-1)".
floor_frames() {
  local first="${1%%-*}"
  echo "$first-$(( first + $2 - 1 ))"
}

# noise_floor_render SCENE DIR FRAMES SPP RENDER_ARG...: SCENE's reference at SPP samples per pixel, frames FRAMES,
# into DIR/reference.####.exr; RENDER_ARG are the reference's own render-gbuffer options (size, fps, payload,
# --reference-jitter) so that only the sample count differs. Kept when REUSE_RENDER=1 and DIR exists.
noise_floor_render() {
  local scene="$1" dir="$2" frames="$3" spp="$4"
  shift 4
  if [[ "${REUSE_RENDER:-0}" == 1 && -d "$dir" ]]; then
    echo "== $(basename "${scene%.*}"): reusing $dir (noise floor)" >&2
    return 0
  fi
  echo "== $(basename "${scene%.*}"): the reference at $spp spp, frames $frames (noise floor)" >&2
  "$(tool_path render-gbuffer)" "$scene" --out "$dir" --frames "$frames" --outputs reference --reference-spp "$spp" "$@"
}

# noise_floor_score REFERENCE FLOOR FRAMES JSON: compare's JSON (one sequence, "reference") of the reference
# sequence REFERENCE scored against FLOOR (its 4x render), frames FRAMES: the input of tables.py noise-floor.
noise_floor_score() {
  "$(tool_path compare)" --reference "$2" "$1" --names reference --frames "$3" --json "$4" > /dev/null
}
