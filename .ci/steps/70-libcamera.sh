#!/usr/bin/env bash
# libcamera's virtual camera (issue 19): build libcamera from Debian's source package with only
# the virtual pipeline handler (make libcamera-virtual: about 3.5 min on 2 cores), eis-libcamera
# against it, then run it on the virtual camera playing a rendered shaky clip
# (tests/checks/libcamera-virtual.sh: the camera listed, every frame captured through the memfd
# buffer fallback, the images played in order, the same bytes as home-stab, the jitter removed).
# Any failure, or a check that did not run, fails CI.
set -euo pipefail
cd "$(dirname "$0")/../.."
export DEBIAN_FRONTEND=noninteractive
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
# meson, ninja and python3's ply/jinja2/yaml build libcamera; libyaml and libyuv it links
# (without them meson would download its own); g++ and pkg-config build eis-libcamera; ffmpeg
# writes the JPEGs; numpy measures the jitter
$SUDO apt-get install -y -qq --no-install-recommends meson ninja-build pkg-config g++ python3-ply \
  python3-jinja2 python3-yaml libyaml-dev libyuv-dev ffmpeg util-linux > /dev/null
python3 -c 'import numpy' 2> /dev/null || python3 -m pip install -q numpy

BUILD=${LIBCAMERA_CI_BUILD:-build}
start=$(date +%s)
make -j2 BUILD=$BUILD libcamera-virtual
echo "70-libcamera: libcamera and eis-libcamera built in $(( $(date +%s) - start )) s"

# shellcheck source=../checks.sh
. .ci/checks.sh
set +eu
# shellcheck source=/dev/null
. tests/checks/libcamera-virtual.sh
set -eu
require_checks libcamera_virtual_lists_camera libcamera_virtual_capture libcamera_virtual_stabilises
