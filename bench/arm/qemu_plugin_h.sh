#!/usr/bin/env bash
# Puts qemu's plugin API header (include/qemu/qemu-plugin.h, GPL-2.0-or-later, so not kept in
# this repository) into DIR, from the Debian source package of the qemu that is installed:
# `apt-get source --download-only qemu` (adds a deb-src entry for Debian's main archive when
# apt has none, which needs root or sudo), then only that one file out of the upstream tarball.
# A plugin must be built against the header of the qemu version that loads it (7.2 on Debian 12).
#   bench/arm/qemu_plugin_h.sh DIR
set -euo pipefail
dir=$1
[ -s "$dir/qemu-plugin.h" ] && exit 0
mkdir -p "$dir"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
if ! apt-cache showsrc qemu 2> /dev/null | grep -c '^Package: qemu' > /dev/null; then
  echo "qemu_plugin_h: adding a deb-src entry (/etc/apt/sources.list.d/libhome-deb-src.sources)"
  codename=$(. /etc/os-release && echo "$VERSION_CODENAME")
  printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: %s\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
    "$codename" | $SUDO tee /etc/apt/sources.list.d/libhome-deb-src.sources > /dev/null
  $SUDO apt-get update -qq
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
chmod 755 "$tmp"  # apt-get source downloads as the _apt user
(cd "$tmp" && apt-get source --download-only -qq qemu > /dev/null)
orig=$(ls "$tmp"/qemu_*.orig.tar.* | head -n 1)
member=$(tar -tf "$orig" | grep '/include/qemu/qemu-plugin.h$' | head -n 1)
tar -xf "$orig" -C "$tmp" "$member"
cp "$tmp/$member" "$dir/qemu-plugin.h"
echo "qemu_plugin_h: $(basename "$orig"): $member -> $dir/qemu-plugin.h"
