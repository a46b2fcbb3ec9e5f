#!/usr/bin/env bash
# The pipelines' method lists come from the tools (pipelines/lib.sh, pipelines/workflow/scripts/methods.py):
#  - the built tools: methods_of and method_args of lib.sh against what the tools print,
#  - a stand-in tool with --list-methods-json (the machine-readable registry): names, a named variant's
#    arguments, name suffixes and statefulness are the JSON's,
#  - a stand-in tool without --list-methods-json: an error that says to rebuild it,
#  - require_tools on a missing tool: exit 2 naming the command that builds it.
# Usage: check_methods.sh BUILD_DIR WORK_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="$(cd "$1" && pwd)"
work="$2"
rm -rf "$work"
mkdir -p "$work"
fail() { echo "check_methods.sh: $*" >&2; exit 1; }
methods="$here/pipelines/workflow/scripts/methods.py"

# lib.sh against the built tools.
out="$(bash -c 'source "$1/pipelines/lib.sh"; use_build "$2"
  echo "up=$(methods_of upsample-st)"
  echo "morph=$(methods_of morph-120hz)"
  echo "filter=$(methods_of filter-phlm)"
  echo "fav=$(method_args upsample-st herzog-favor-spatial)"
  echo "demod=$(method_args upsample-st herzog-demod)"' _ "$here" "$build")"
expect() { grep -qxF "$1" <<< "$out" || fail "expected '$1' in: $out"; }
morph_names="$("$build/apps/morph-120hz/morph-120hz" --list-methods | cut -f1 | paste -sd' ')"
expect "morph=$morph_names"
expect "fav=--method herzog --favor-spatial"
expect "demod=--method herzog --demodulate"
grep -q '^up=spatial temporal herzog' <<< "$out" || fail "upsample-st's methods: $out"
grep -q '^filter=.*phlm.*taa' <<< "$out" || fail "filter-phlm's methods: $out"
[[ "$(python3 "$methods" stateful "$build/apps/upsample-st/upsample-st" spatial)" == false ]] || fail "spatial keeps a history?"
[[ "$(python3 "$methods" stateful "$build/apps/upsample-st/upsample-st" herzog)" == true ]] || fail "herzog keeps none?"
if python3 "$methods" args "$build/apps/upsample-st/upsample-st" no-such-method 2> "$work/err"; then
  fail "an unknown name was accepted"
fi
grep -q "unknown method 'no-such-method'" "$work/err" || fail "unknown name: $(cat "$work/err")"

# A stand-in tool with the JSON form (and a tab-separated listing with one name suffix).
mkdir -p "$work/json/apps/demo-tool"
cat > "$work/json/apps/demo-tool/demo-tool" <<'SH'
#!/bin/sh
case "$1" in
  --list-methods-json) cat <<'JSON'
[{"name": "alpha", "method": "alpha", "args": [], "summary": "a", "stateful": false, "implementations": ["cpu"]},
 {"name": "beta", "method": "beta", "args": [], "summary": "b", "stateful": true, "implementations": ["cpu"]},
 {"name": "beta-fast", "method": "beta", "args": ["--fast", "2"], "summary": "c", "stateful": true,
  "implementations": ["cpu"]},
 {"suffix": "-x", "args": ["--extra"], "summary": "x"}]
JSON
  ;;
  *) exit 1 ;;
esac
SH
chmod +x "$work/json/apps/demo-tool/demo-tool"
tool="$work/json/apps/demo-tool/demo-tool"
[[ "$(python3 "$methods" names "$tool" | paste -sd' ')" == "alpha beta" ]] || fail "JSON names"
[[ "$(python3 "$methods" args "$tool" beta-fast-x)" == $'beta-fast-x\t--method beta --fast 2 --extra' ]] ||
  fail "JSON variant with a suffix: $(python3 "$methods" args "$tool" beta-fast-x)"
[[ "$(python3 "$methods" stateful "$tool" alpha)" == false ]] || fail "JSON stateful of alpha"
[[ "$(python3 "$methods" stateful "$tool" beta)" == true ]] || fail "JSON stateful of beta"

# A tool without the JSON form: an error saying to rebuild it.
mkdir -p "$work/old/apps/filter-phlm"
printf '#!/bin/sh\nexit 1\n' > "$work/old/apps/filter-phlm/filter-phlm"
chmod +x "$work/old/apps/filter-phlm/filter-phlm"
if python3 "$methods" names "$work/old/apps/filter-phlm/filter-phlm" 2> "$work/err"; then
  fail "a tool without --list-methods-json was accepted"
fi
grep -q "filter-phlm has no --list-methods-json: rebuild it" "$work/err" || fail "old tool: $(cat "$work/err")"

# require_tools on a missing tool.
if bash -c 'source "$1/pipelines/lib.sh"; use_build "$2"; require_tools compare' _ "$here" "$work/json" 2> "$work/err"; then
  fail "require_tools accepted a missing tool"
else
  rc=$?
fi
[[ $rc == 2 ]] || fail "require_tools exited $rc, not 2"
grep -q "compare is missing: build it first (cmake .*--target compare)" "$work/err" || fail "message: $(cat "$work/err")"
echo "check_methods.sh: ok"
