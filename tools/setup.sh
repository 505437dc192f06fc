#!/usr/bin/env bash
# Installs what Obscura needs on Debian 12 (idempotent; quick when everything is present).
# The Python module (python/) needs python3-dev, pybind11-dev and python3-numpy.
# --tests: also what only some tests need: Slurm and munge for tests/farm/slurm_test.sh, which
# starts and stops a one-node cluster of its own; pytest for the Python API's tests. (On a systemd host Debian's packages enable
# munge.service, and slurmctld/slurmd units that do not start without /etc/slurm/slurm.conf.)
set -euo pipefail
with_tests=0
for arg in "$@"; do
  case $arg in
    --tests) with_tests=1 ;;
    *) echo "usage: tools/setup.sh [--tests]" >&2; exit 2 ;;
  esac
done
packages=(
  cmake ninja-build g++ pkg-config git
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools glslang-tools
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev zlib1g-dev libopenimageio-dev
  libcli11-dev libfmt-dev libgtest-dev libgmock-dev libbenchmark-dev
  libembree-dev
  libglfw3-dev libimgui-dev xvfb xauth
  clang libclang-rt-14-dev
  python3-matplotlib
  python3-dev pybind11-dev python3-numpy
)
((with_tests)) && packages+=(slurm-wlm munge python3-pytest)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
