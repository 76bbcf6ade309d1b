#!/usr/bin/env bash
# GStreamer (issue 19): with GStreamer's development packages and tools installed, build the
# homestab plugin and its harness tests, then run them and the gst-launch checks
# (tests/checks/gst.sh: gst-inspect, a pipeline per format, the live latency, byte identity
# with home-stab through y4mdec/y4menc, make install). Headless; any failure, or a check that
# did not run, fails CI.
set -euo pipefail
cd "$(dirname "$0")/../.."
export DEBIAN_FRONTEND=noninteractive
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends pkg-config libgstreamer1.0-dev \
  libgstreamer-plugins-base1.0-dev gstreamer1.0-tools gstreamer1.0-plugins-good \
  gstreamer1.0-plugins-bad > /dev/null

BUILD=${GST_CI_BUILD:-build}
make -j2 BUILD=$BUILD all
for f in lib/gstreamer-1.0/libgsthome.so bin/home-gst-tests; do
  [ -e "$BUILD/$f" ] || { echo "60-gst: $f was not built"; exit 1; }
done

# shellcheck source=../checks.sh
. .ci/checks.sh
# a writable registry in the build directory, this plugin on the path (the harness tests load
# only the element compiled into them and ignore both)
export GST_REGISTRY="$PWD/$BUILD/gst-registry.bin"
export GST_PLUGIN_PATH="$PWD/$BUILD/lib/gstreamer-1.0"
unit_tests "$BUILD/bin/home-gst-tests" home-gst-tests
# gst.sh checks make install's result in $tmp/dest, as tests/run.sh lays it out
make -s install BUILD=$BUILD DESTDIR="$tmp/dest" PREFIX=/opt/home > /dev/null
set +eu
# shellcheck source=/dev/null
. tests/checks/gst.sh
set -eu
require_checks gst_inspect gst_pipeline_I420 gst_pipeline_NV12 gst_pipeline_YUY2 gst_pipeline_GRAY8 \
  gst_live_latency gst_same_bytes_as_home_stab_lookahead8 gst_make_install
