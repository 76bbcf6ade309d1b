#!/usr/bin/env bash
# Quick subset of the evaluation against ORB, AKAZE and LSD/LBD (bench/eval). Fails when the
# scripts crash or home-register errors on a generated pair; accuracy is the report's business.
set -euo pipefail
cd "$(dirname "$0")/../.."
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
# make eval-quick pip-installs numpy, OpenCV (contrib) and matplotlib; Debian's own python3
# has no pip until python3-pip is installed.
if ! python3 -m pip --version > /dev/null 2>&1; then
  $SUDO apt-get install -y -qq --no-install-recommends python3-pip > /dev/null
fi
make eval-quick
test -s build/eval-cache/quick/results.md
grep -q "^| linear pairs" build/eval-cache/quick/results.md
