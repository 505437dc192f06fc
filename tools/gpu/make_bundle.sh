#!/bin/bash
# make_bundle.sh BUNDLE_DIR [BUILD_DIR] — obscura packed to travel to a machine with a GPU but none
# of Obscura's build dependencies (the device tool's bare CUDA image), for tools/gpu/benchmarks.sh.
#
# The build leaves out OpenImageIO (its libraries and theirs come to ~400 MB; PNG still works
# through stb, EXR is read by host/io/exr_reader.cpp and written uncompressed) and Embree (the CPU
# baseline: 44 MB, and a GPU is measured against the issue's absolute figures, not against the
# CPU). BUNDLE_DIR gets the binary, the shared libraries it needs beyond glibc and libstdc++ (fmt,
# stb, zlib, GLFW and X11's client libraries), the benchmark scenes from ../shared/scenes and the
# modern hall's photographs from tests/data/photos (photos/). The Vulkan loader travels
# separately (.gl, see .library/device/README.md).
set -euo pipefail
bundle=${1:?usage: make_bundle.sh BUNDLE_DIR [BUILD_DIR] (.gpu-bundle is ignored by git)}
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
build=${2:-/tmp/obscura-gpu-build}
scenes=$source_dir/../shared/scenes

cmake -S "$source_dir" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DOBSCURA_WITH_OPENIMAGEIO=OFF \
  -DOBSCURA_WITH_EMBREE=OFF -DOBSCURA_BUILD_TESTS=OFF -DOBSCURA_FUZZ_LOADER=OFF >/dev/null
cmake --build "$build" --target obscura

rm -rf "$bundle"
mkdir -p "$bundle/lib" "$bundle/scenes"
cp "$build/obscura" "$bundle/"
# Everything ldd resolves except the C and C++ runtimes, which every Linux image has (newer).
ldd "$build/obscura" | awk '/=> \//{print $3}' |
  grep -Ev '/(libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s|libvulkan)\.so' |
  while read -r lib; do cp -L "$lib" "$bundle/lib/"; done
for scene in modern-hall sponza; do cp -r "$scenes/$scene" "$bundle/scenes/"; done
# The hall's photographs for `recover` (its gather on the device): the six shots and the answer key.
mkdir -p "$bundle/photos/modern-hall"
cp "$source_dir"/tests/data/photos/modern-hall/{lights.json,albedo.exr,photo-00?.exr} "$bundle/photos/modern-hall/"
du -sh "$bundle"
