#!/bin/bash
# Runs the GPU agreement tests and the kernel benchmarks on a GPU machine that has only its driver (docs/gpu.md,
# "On an NVIDIA H200"; shared/notes/platform.md, "EGL").
#
# Prepare on the build machine, in one folder DIR: gpu_test, gpu_morph_test, gpu_benchmark, upsample_benchmark,
# phlm_bench, morph_benchmark and flip_benchmark from build/ci (stripped), libtbb.so.12, libbenchmark.so.1debian,
# libstdc++.so.6 and libgcc_s.so.1 from /lib/x86_64-linux-gnu, and glvnd's loaders as .deb files in DIR/debs
# (`apt-get download libegl1 libglvnd0 libopengl0`). On the GPU machine, as root:
#   tests/benchmarks/gpu/device_run.sh DIR OUT
# It unpacks the loaders, samples the GPU's clocks while it runs, and writes every result under OUT: machine.txt,
# clocks.csv, gpu_tests.txt, and one Google Benchmark JSON per step. Each step has its own time limit, so a hung
# step costs that limit and the next step still runs.
set -u
dir=$(cd "$1" && pwd) out=$(mkdir -p "$2" && cd "$2" && pwd)
for f in "$dir"/debs/*.deb; do [ -e "$f" ] && dpkg -x "$f" /; done
ldconfig
for v in /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json /usr/share/glvnd/egl_vendor.d/10_nvidia.json; do
  [ -e "$v" ] && export __EGL_VENDOR_LIBRARY_FILENAMES=$v && break
done
export LD_LIBRARY_PATH=$dir
cd "$dir"
step() { echo "== $(date +%T) $*"; }
{ lscpu; nvidia-smi -L; } > "$out/machine.txt" 2>&1
grep -m1 "Model name" "$out/machine.txt"; echo "AVX-512: $(grep -c avx512f /proc/cpuinfo) of $(nproc) CPUs"
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,power.draw,utilization.gpu --format=csv,noheader -lms 250 \
  > "$out/clocks.csv" 2>&1 &
sampler=$!
json() { echo "--benchmark_out=$out/$1.json"; }

step "agreement tests on the GPU"
timeout 120 ./gpu_test > "$out/gpu_tests.txt" 2>&1; echo "gpu_test rc=$?"
timeout 90 ./gpu_morph_test >> "$out/gpu_tests.txt" 2>&1; echo "gpu_morph_test rc=$?"
grep -E "^\[  (PASSED|FAILED) |^\[  SKIPPED \] [0-9]|^\[==========\] [0-9]+ tests|^\[  FAILED  \]" "$out/gpu_tests.txt"

step "GPU kernels at the papers' sizes, with the copy kernel's bound"
# Every iteration uploads a frame (10-20 ms on the host) around kernels of 0.03-2 ms: fix the iteration count.
GPU_BENCH_ITERATIONS=20 timeout 180 ./gpu_benchmark --benchmark_repetitions=5 $(json gpu) \
  --benchmark_filter='BM_Copy/(1920|1280|1024)/|BM_[A-Z][a-z]+/(1920|1280|1024)/' 2>&1 | grep _median | cut -c1-140

step "the CPU implementations on every core (compute against compute)"
agg="--benchmark_repetitions=3 --benchmark_report_aggregates_only=true"
timeout 90 ./upsample_benchmark --benchmark_filter='BM_(Upsample|Stream)/' $agg $(json upsample) 2>&1 | grep median
timeout 60 ./phlm_bench --benchmark_filter='threads:0/' $agg $(json phlm) 2>&1 | grep median
timeout 60 ./morph_benchmark --benchmark_filter='1024x3/0/' $agg $(json morph) 2>&1 | grep median

step "FLIP on one thread at the v3 (AVX2) level and at the detected level"
one="--benchmark_filter=(PsnrSsim|FlipLdr)_1080p/1/ --benchmark_repetitions=5 --benchmark_report_aggregates_only=true"
TEMPORAL_ISA=v3 timeout 60 taskset -c 3 ./flip_benchmark $one $(json flip_v3) 2>&1 | grep median
timeout 60 taskset -c 3 ./flip_benchmark $one $(json flip_auto) 2>&1 | grep median

kill "$sampler"
step done
