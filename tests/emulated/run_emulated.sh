#!/usr/bin/env bash
# run_emulated.sh MODEL LEVEL PROGRAM [ARGS...]: runs PROGRAM on the CPU model MODEL emulated by qemu-user
# (`qemu-x86_64 -cpu MODEL`), with TEMPORAL_ISA_EXPECTED=LEVEL for the tests that check the level the dispatch
# chose (tests/core/isa_test.cpp, Isa.EmulatedCpuRunsItsLevel). Exit 77 (CTest SKIP_RETURN_CODE) without
# qemu-x86_64. An instruction the emulated CPU lacks kills the program with SIGILL ("qemu: uncaught target signal
# 4 (Illegal instruction)"), which CTest reports as a failure.
#
# qemu-user emulates the process it starts only: a program that PROGRAM starts (a tool run by a CLI test) runs on
# the host CPU, so the CLI tests are left out of the emulated runs (tests/emulated/CMakeLists.txt).
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: run_emulated.sh MODEL LEVEL PROGRAM [ARGS...]" >&2; exit 2; }
model=$1 level=$2
shift 2
if ! command -v qemu-x86_64 >/dev/null; then
  echo "run_emulated.sh: SKIP: qemu-x86_64 not found; install Debian's qemu-user (./setup.sh does) to run the" \
       "unit tests on an emulated $model ($level) CPU" >&2
  exit 77
fi
# The level must come from the emulated CPU, not be forced.
unset TEMPORAL_ISA
export TEMPORAL_ISA_EXPECTED=$level
exec qemu-x86_64 -cpu "$model" "$@"
