#!/usr/bin/env bash
# ARM instructions per frame (make bench-arm): builds the library, home-arm-frames and home-stab
# for aarch64 and armv7 (static, with link maps), runs them under qemu-user with the counting
# plugin (bench/arm/insn_count.c) and prints the table (bench/arm/report.py). Per frame is the
# difference of two runs, so set-up and the first frame cancel:
#   registration (home_video_config): home-arm-frames --frames 3 minus --frames 1, halved;
#   stabiliser: home-stab (fixed crop, no lookahead: as live) on a 6-frame generated clip minus
#     the same clip cut after 2 frames, divided by 4 (each frame registered and warped).
# Working set (WORKING_SET=0 skips it): distinct cache lines touched per frame, aarch64.
# Environment: BUILD (native build, for home-stab-clip), SIZES, ARCHES (aarch64 armv7), JOBS.
set -euo pipefail
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
SIZES=${SIZES:-640x360 1280x720 1920x1080}
ARCHES=${ARCHES:-aarch64 armv7}
JOBS=${JOBS:-2}
OUT=$BUILD/bench-arm
mkdir -p "$OUT"

need() { command -v "$1" > /dev/null || { echo "bench-arm: $1 not found: apt-get install $2"; exit 1; }; }
need python3 python3
need llvm-mca llvm
for arch in $ARCHES; do
  case $arch in
    aarch64) need qemu-aarch64 qemu-user; need aarch64-linux-gnu-gcc "gcc-aarch64-linux-gnu libc6-dev-arm64-cross" ;;
    armv7) need qemu-arm qemu-user; need arm-linux-gnueabihf-gcc "gcc-arm-linux-gnueabihf libc6-dev-armhf-cross" ;;
    *) echo "bench-arm: unknown arch $arch (aarch64, armv7)"; exit 1 ;;
  esac
done

# the plugin, against the header of the installed qemu (static qemu builds cannot load plugins)
bash bench/arm/qemu_plugin_h.sh "$OUT/qemu-include"
plugin=$OUT/libinsn_count.so
if [ ! -s "$plugin" ] || [ bench/arm/insn_count.c -nt "$plugin" ]; then
  gcc -shared -fPIC -O2 -Wall -Wextra -Werror -I"$OUT/qemu-include" bench/arm/insn_count.c -o "$plugin"
fi

# the programs per target, linked static (every executed instruction has a symbol) with a map
for arch in $ARCHES; do
  cross=$([ "$arch" = aarch64 ] && echo aarch64-linux-gnu- || echo arm-linux-gnueabihf-)
  b=$OUT/$arch
  for prog in home-arm-frames home-stab; do
    make -s -j"$JOBS" CROSS_COMPILE=$cross BUILD="$b" LDFLAGS="-static -Wl,-Map=$b/$prog.map" \
      "$b/bin/$prog" 2>&1 | grep -v '^stab: skipped' || true
    [ -x "$b/bin/$prog" ] || { echo "bench-arm: $b/bin/$prog not built"; exit 1; }
  done
done

# the clips: 6 frames, and the same cut after 2
make -s "$BUILD/bin/home-stab-clip" 2>&1 | grep -v '^stab: skipped' || true
for size in $SIZES; do
  w=${size%x*}; h=${size#*x}
  clip=$OUT/clip-$size
  if [ ! -s "$clip-6.y4m" ]; then
    "$BUILD/bin/home-stab-clip" --scene structured --frames 6 --width "$w" --height "$h" --shake 4 \
      --rot 0.4 --pan 80 --seed 3 "$clip-6.y4m" "$clip.csv"
    python3 - "$clip-6.y4m" "$clip-2.y4m" 2 "$w" "$h" << 'PY'
import sys
src, dst, n, w, h = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
data = open(src, 'rb').read()
header = data.index(b'\n') + 1
frame = len(b'FRAME\n') + w * h + 2 * ((w + 1) // 2) * ((h + 1) // 2)
open(dst, 'wb').write(data[:header + n * frame])
PY
  fi
done

# the runs, JOBS at a time; each writes RUN.blocks ("vaddr insns executions" per block)
runs=$OUT/runs.txt
: > "$runs"
for arch in $ARCHES; do
  if [ "$arch" = aarch64 ]; then qemu="qemu-aarch64 -cpu cortex-a72"; else qemu="qemu-arm -cpu cortex-a15"; fi
  for size in $SIZES; do
    w=${size%x*}; h=${size#*x}
    for n in 1 3; do
      echo "$qemu -plugin $plugin,out=$OUT/$arch-video-$size-$n.blocks $OUT/$arch/bin/home-arm-frames --width $w --height $h --frames $n" >> "$runs"
    done
    for n in 2 6; do
      echo "$qemu -plugin $plugin,out=$OUT/$arch-stab-$size-$n.blocks $OUT/$arch/bin/home-stab --quiet --fixed-crop --threads 1 --lookahead 0 $OUT/clip-$size-$n.y4m /dev/null" >> "$runs"
    done
  done
done
# the working set (aarch64 only: the data layout hardly differs by target): distinct 64-byte
# lines loaded or stored per frame, split at each entry of home_extract (video) and
# home_stab_push (stab); a few frames each, every memory access through the plugin (slower)
if [ "${WORKING_SET:-1}" = 1 ] && [[ " $ARCHES " == *" aarch64 "* ]]; then
  for size in $SIZES; do
    w=${size%x*}; h=${size#*x}
    for task in video stab; do
      prog=$([ $task = video ] && echo home-arm-frames || echo home-stab)
      fn=$([ $task = video ] && echo home_extract || echo home_stab_push)
      mark=$(aarch64-linux-gnu-nm "$OUT/aarch64/bin/$prog" | awk -v f="$fn" '$3 == f {print $1}')
      args=$([ $task = video ] && echo "--width $w --height $h --frames 4" ||
        echo "--quiet --fixed-crop --threads 1 --lookahead 0 $OUT/clip-$size-6.y4m /dev/null")
      echo "qemu-aarch64 -cpu cortex-a72 -plugin $plugin,out=$OUT/wset-$task-$size.blocks,mark=$mark $OUT/aarch64/bin/$prog $args" >> "$runs"
    done
  done
fi
# a run whose output is newer than its program and the plugin is kept (FORCE=1 redoes all)
todo=$OUT/todo.txt
: > "$todo"
while read -r line; do
  out=$(echo "$line" | sed 's/.*,out=\([^ ,]*\).*/\1/')
  prog=$(echo "$line" | awk '{for (i = 1; i <= NF; i++) if ($i ~ /\/bin\//) {print $i; exit}}')
  if [ "${FORCE:-0}" = 1 ] || [ ! -s "$out" ] || [ "$prog" -nt "$out" ] || [ "$plugin" -nt "$out" ]; then
    echo "$line" >> "$todo"
  fi
done < "$runs"
echo "bench-arm: $(wc -l < "$todo") of $(wc -l < "$runs") runs to do under qemu, $JOBS at a time (minutes)"
xargs -P "$JOBS" -I{} -d '\n' sh -c '{} > /dev/null || echo "bench-arm: failed: {}"' < "$todo"
python3 bench/arm/report.py --out "$OUT" --arches "$ARCHES" --sizes "$SIZES"
