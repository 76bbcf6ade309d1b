#!/usr/bin/env bash
# Build libcamera from source with only the virtual pipeline handler (a camera without a device,
# libcamera >= 0.4.0), installed into a private prefix: what `make libcamera-virtual` and CI's
# .ci/steps/70-libcamera.sh run eis-libcamera against. Nothing is installed system-wide.
#
#   tests/support/build-libcamera-virtual.sh OUT_DIR
#
# OUT_DIR/prefix      the installed libcamera (lib/pkgconfig/libcamera.pc, share/libcamera/...)
# OUT_DIR/VERSION     the version built, written last: a finished build
# OUT_DIR/src         the downloaded source package
#
# The source: LIBCAMERA_SRC=<unpacked tree or .tar.*> when set; else Debian's source package,
# fetched with `apt-get source` through a private apt configuration (OUT_DIR/apt; the system's
# sources lists are not touched): trixie's (0.4.0) when the archive still serves its files, else
# sid's (0.7.2 on 2026-11-26). Debian's pool keeps only current versions, so the version is
# whatever those suites hold; OUT_DIR/VERSION records it, and eis-libcamera builds against any
# from 0.0.3 on. Build dependencies (Debian 12): meson ninja-build pkg-config python3-ply
# python3-jinja2 python3-yaml libyaml-dev libyuv-dev g++ dpkg-dev (for the source unpack).
#
# Cache: a finished build whose OUT_DIR/STAMP matches this script's checksum is reused as it is
# (no network); remove OUT_DIR to rebuild. JOBS (default 2) sets ninja's parallelism.
set -euo pipefail
out=${1:?usage: build-libcamera-virtual.sh OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
jobs=${JOBS:-2}
stamp="$(sha256sum "$0" | cut -c1-16) ${LIBCAMERA_SRC:-debian}"
if [ -f "$out/VERSION" ] && [ -f "$out/STAMP" ] && [ "$(cat "$out/STAMP")" = "$stamp" ] &&
   [ -f "$out/prefix/lib/pkgconfig/libcamera.pc" ]; then
  echo "libcamera-virtual: cached $(cat "$out/VERSION") in $out/prefix"
  exit 0
fi
rm -f "$out/VERSION" "$out/STAMP"
for tool in meson ninja pkg-config; do
  command -v $tool > /dev/null || { echo "libcamera-virtual: $tool not found (apt-get install meson ninja-build pkg-config python3-ply python3-jinja2 python3-yaml libyaml-dev libyuv-dev)" >&2; exit 2; }
done
start=$(date +%s)
# libcamera's code generators run on the `python3` found first on PATH; a user-installed python3
# ahead of Debian's lacks the modules Debian's packages provide: then use Debian's for the build
pymods='import ply, jinja2, yaml'
if ! python3 -c "$pymods" 2> /dev/null; then
  if /usr/bin/python3 -c "$pymods" 2> /dev/null; then
    mkdir -p "$out/pybin" && ln -sf /usr/bin/python3 "$out/pybin/python3"
    export PATH="$out/pybin:$PATH"
  else
    echo "libcamera-virtual: python3 lacks ply, jinja2 or yaml (apt-get install python3-ply python3-jinja2 python3-yaml)" >&2
    exit 2
  fi
fi

# 1. the source tree
src=""
if [ -n "${LIBCAMERA_SRC:-}" ]; then
  if [ -d "$LIBCAMERA_SRC" ]; then src=$(cd "$LIBCAMERA_SRC" && pwd)
  else
    rm -rf "$out/src" && mkdir -p "$out/src"
    tar -xf "$LIBCAMERA_SRC" -C "$out/src"
    src=$(dirname "$(ls -d "$out"/src/*/meson.build | head -1)")
  fi
else
  apt_dir="$out/apt"
  mkdir -p "$apt_dir/lists/partial" "$apt_dir/cache/archives/partial"
  printf 'deb-src http://deb.debian.org/debian %s main\n' trixie sid > "$apt_dir/sources.list"
  apt_opts=(-o Dir::Etc::SourceList="$apt_dir/sources.list" -o Dir::Etc::SourceParts=/dev/null
            -o Dir::State::Lists="$apt_dir/lists" -o Dir::Cache="$apt_dir/cache"
            -o APT::Sandbox::User=root -qq)
  apt-get "${apt_opts[@]}" update
  rm -rf "$out/src" && mkdir -p "$out/src"
  for suite in trixie sid; do
    # --download-only then tar: no dpkg-source needed, and Debian's patches (packaging only)
    # are left out
    if (cd "$out/src" && apt-get "${apt_opts[@]}" source --download-only "libcamera/$suite" > "$out/src/apt-$suite.log" 2>&1); then
      orig=$(ls "$out"/src/libcamera_*.orig.tar.* | head -1)
      tar -xf "$orig" -C "$out/src"
      src=$(dirname "$(ls -d "$out"/src/*/meson.build | head -1)")
      echo "libcamera-virtual: source $(basename "$orig") (Debian $suite)"
      break
    fi
    echo "libcamera-virtual: Debian $suite's source is not served: $(grep -m1 '^E:' "$out/src/apt-$suite.log" || true)"
    rm -f "$out"/src/libcamera_*
  done
  [ -n "$src" ] || { echo "libcamera-virtual: no libcamera source package could be fetched" >&2; exit 2; }
fi
version=$(sed -n "s/^ *version *: *'\([0-9.]*\)'.*/\1/p" "$src/meson.build" | head -1)
[ -d "$src/src/libcamera/pipeline/virtual" ] ||
  { echo "libcamera-virtual: libcamera $version has no virtual pipeline handler (needs 0.4.0 or later)" >&2; exit 2; }

# 2. configure: the virtual pipeline only; no IPA, tools, bindings, docs, tracing or udev.
#    libyuv and libyaml come from the system (otherwise meson would download subprojects);
#    warnings stay warnings (a newer compiler than upstream's CI must not stop the build)
rm -rf "$out/build" "$out/prefix"
meson setup "$out/build" "$src" --prefix="$out/prefix" --libdir=lib --buildtype=release \
  -Dwerror=false -Dpipelines=virtual -Dipas=[] -Dcam=disabled -Dqcam=disabled \
  -Dgstreamer=disabled -Dlc-compliance=disabled -Ddocumentation=disabled -Dtracing=disabled \
  -Dpycamera=disabled -Dudev=disabled -Dv4l2=false -Dtest=false -Dandroid=disabled \
  --wrap-mode=nodownload > "$out/meson-setup.log" 2>&1 ||
  { tail -30 "$out/meson-setup.log" >&2; exit 2; }
ninja -C "$out/build" -j "$jobs" > "$out/ninja.log" 2>&1 || { tail -40 "$out/ninja.log" >&2; exit 2; }
ninja -C "$out/build" install > "$out/install.log" 2>&1 || { tail -20 "$out/install.log" >&2; exit 2; }
# the camera list: libcamera installs only virtual.yaml.example (no virtual.yaml: no camera);
# its example cameras (test patterns) until a user or a test puts another in its place
conf="$out/prefix/share/libcamera/pipeline/virtual"
[ -f "$conf/virtual.yaml" ] || cp "$conf/virtual.yaml.example" "$conf/virtual.yaml"
# what is left is the prefix (the objects, the unpacked source and apt's lists: 150 MB)
rm -rf "$out/build" "$out/apt" "$out/pybin"
[ -n "${LIBCAMERA_SRC:-}" ] || rm -rf "$src"
echo "$stamp" > "$out/STAMP"
echo "$version" > "$out/VERSION"
echo "libcamera-virtual: libcamera $version built in $(( $(date +%s) - start )) s into $out/prefix"
