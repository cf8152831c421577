#!/usr/bin/env bash
# Installs what softrast needs to build and test on Debian 12, all from Debian's packages.
set -euo pipefail
packages=(
  cmake g++ make pkg-config  # the toolchain
  libglm-dev                 # vectors and matrices with OpenGL's conventions
  libtinyobjloader-dev       # OBJ parsing
  libstb-dev                 # TGA encoding (stb_image_write); the reference tools' reading
  libspng-dev                # PNG decoding: fuzzed upstream, size limits before allocation
  libjpeg62-turbo-dev        # JPEG decoding (size known before allocation) and JPEG writing
  zlib1g-dev                 # PNG writing (level 1, strips compressed in parallel); test PNGs
  libcli11-dev               # the command line
  nlohmann-json3-dev         # JSON: batch job lines, --json records, glTF (header-only)
  libtinygltf-dev            # glTF 2.0 / GLB parsing (compiled in from its header)
  libgtest-dev               # the test suite
  libbenchmark-dev           # the micro-benchmarks (bench/), built but never run by the tests
  libosmesa6-dev libgl-dev   # Mesa llvmpipe, the reference renderer of the difference tests
  libsdl2-dev                # the live viewer's window, input and texture upload (softrast view)
  xvfb xdotool x11-apps      # the viewer test: a virtual X server, input events, xwd capture
)
sudo=""
if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
echo "install-deps: ${#packages[@]} packages present"
