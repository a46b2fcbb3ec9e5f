#!/usr/bin/env bash
# The suite's two set-up commands (README.md):
#   ./setup.sh demo   install what is missing, build the release preset, run the end-to-end demo -> report/demo/
#   ./setup.sh test   install what is missing, build the ci preset, run every test (CI runs exactly this)
# Both install Debian 12 packages with apt-get when they are missing (as root, or through sudo).
set -euo pipefail
cd "$(dirname "$0")"

PACKAGES=(
  cmake ninja-build g++ pkg-config
  libopenimageio-dev openimageio-tools libopenexr-dev
  libopencolorio-dev opencolorio-tools
  libtinygltf-dev libstb-dev nlohmann-json3-dev libglm-dev
  libosmesa6-dev libegl-dev libegl-mesa0
  libvtk9-dev xvfb xauth librsvg2-dev poppler-utils
  libtbb-dev libcli11-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  snakemake slurm-wlm munge python3
  clang-14 libclang-rt-14-dev
  ffmpeg fonts-dejavu-core chromium
  qemu-user
)

say() { printf 'setup.sh: %s\n' "$*" >&2; }

install_missing() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  say "installing ${#missing[@]} Debian packages: ${missing[*]}"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { say "not root and no sudo: install these packages first: ${missing[*]}"; exit 1; }
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -qq
  "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
  local preset=$1
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" -j "$(nproc)"
}

case "${1:-}" in
  demo)
    install_missing
    build release
    exec bash pipelines/demo.sh build/release "${2:-report/demo}"
    ;;
  test)
    install_missing
    build ci
    # No DISPLAY: the tests exercise compare's own virtual display, as on a headless machine.
    env -u DISPLAY ctest --preset ci
    ;;
  *)
    echo "usage: ./setup.sh demo [REPORT_DIR]   build (release) and run the end-to-end demo" >&2
    echo "       ./setup.sh test                build (ci) and run every test" >&2
    exit 1
    ;;
esac
