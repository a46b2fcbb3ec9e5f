# shellcheck shell=bash
# The set-up every pipeline smoke test (tests/pipelines/check_*.sh, tests/phlm/check_filter_phlm_*.sh) starts with:
#
#   source "$(dirname "${BASH_SOURCE[0]}")/check_lib.sh"   # (tests/phlm: .../../pipelines/check_lib.sh)
#
# The test's arguments are BUILD_DIR OUT_DIR. It turns on strict mode and sets here (the repository root), build
# (BUILD_DIR), out (OUT_DIR, emptied and created) and CHECK (the test's file name, for messages).
set -euo pipefail
# shellcheck disable=SC2034
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
# shellcheck disable=SC2034
CHECK="$(basename "${BASH_SOURCE[1]:-$0}")"
# shellcheck disable=SC2034
build="$1"
out="$2"
rm -rf "$out"
mkdir -p "$out"

# fail MESSAGE [FILE]: prints FILE when it exists (the log or summary that shows what went wrong), then
# "CHECK: MESSAGE" on stderr, and exits 1.
fail() {
  if [[ -f "${2:-}" ]]; then cat "$2" >&2; fi
  echo "$CHECK: $1" >&2
  exit 1
}
