#!/usr/bin/env bash
# Runs one libFuzzer target for a bounded time (the fuzz_<target> CTests; by hand too):
#   run_fuzzer.sh FUZZER WORK_DIR SECONDS MAX_LEN SEED_SPEC...
# SECONDS may instead be runs=N: the fuzzer stops after N executions, however long they take (the fuzz-long
# CTests: 10^6 executions per parser).
# SEED_SPEC is DIR:EXT[,EXT...]: every file under DIR (recursively) with one of the extensions is copied into
# WORK_DIR/seeds (never into the repository); a DIR that does not exist is skipped with a message (the shared
# assets are optional). A DIR starting with SHARED means the shared assets: $TEMPORAL_SHARED_ASSETS, else
# $TEMPORAL_SHARED_DEFAULT (the CTests set it to ../shared/assets beside the source tree). First every committed reproducer in tests/fuzz/regressions/<target>/ runs once, then
# the fuzzer runs on WORK_DIR/corpus (kept between runs) and the seeds. Crashes are written to
# WORK_DIR/crash-*: turn each into a regression file. Exit status: the fuzzer's (0: no crash).
set -euo pipefail
fuzzer="$1" work="$2" seconds="$3" max_len="$4"
shift 4
name="$(basename "$fuzzer")"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
mkdir -p "$work/seeds" "$work/corpus"
shared="${TEMPORAL_SHARED_ASSETS:-${TEMPORAL_SHARED_DEFAULT:-}}"
for spec in "$@"; do
  dir="${spec%%:*}" exts="${spec#*:}"
  [[ "$dir" == SHARED* ]] && dir="$shared${dir#SHARED}"
  if [[ ! -d "$dir" ]]; then
    echo "$name: seed folder $dir is absent: skipped"
    continue
  fi
  IFS=, read -ra list <<<"$exts"
  for ext in "${list[@]}"; do
    while IFS= read -r -d '' f; do
      rel="${f#"$dir"/}"
      cp "$f" "$work/seeds/$(basename "$dir")_${rel//\//_}"
    done < <(find "$dir" -type f -name "*.$ext" -print0)
  done
done
echo "$name: $(ls "$work/seeds" | wc -l) seed files, $(ls "$work/corpus" | wc -l) corpus files"
regressions="$here/regressions/$name"
if compgen -G "$regressions/*" >/dev/null; then
  "$fuzzer" -runs=1 "$regressions"/* 2>&1 | tail -3
fi
if [[ "$seconds" == runs=* ]]; then
  limit=(-runs="${seconds#runs=}")
else
  limit=(-max_total_time="$seconds")
fi
exec "$fuzzer" "${limit[@]}" -timeout=20 -rss_limit_mb=2048 -max_len="$max_len" \
  -print_final_stats=1 -artifact_prefix="$work/crash-" "$work/corpus" "$work/seeds"
