#!/usr/bin/env bash
# Bare-metal build (issue 20): the library compiled with arm-none-eabi-gcc (newlib) for a
# Cortex-A53 (AArch32, NEON) and a Cortex-M7, with no OS: no writable globals, no calls beyond
# mem* and libm, and a firmware image that links without system-call stubs. Prints .text.
set -euo pipefail
cd "$(dirname "$0")/../.."
export DEBIAN_FRONTEND=noninteractive
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
$SUDO apt-get install -y -qq --no-install-recommends gcc-arm-none-eabi libnewlib-arm-none-eabi > /dev/null
make -s -j2 baremetal BUILD=build-baremetal
