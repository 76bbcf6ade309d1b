#!/usr/bin/env bash
# make baremetal's report and checks, per target directory (libhome.a, firmware.elf):
#   .text/.data/.bss of the archive (arm-none-eabi-size, summed over its objects);
#   .data and .bss must be 0 (no writable globals);
#   the functions it takes from the C library must be freestanding ones (mem*, libm, the
#   compiler's run-time helpers): anything else (stdio, getenv, clock, malloc) is an OS
#   dependency and fails;
#   firmware.elf linked (the make rule fails on an undefined system call).
set -u
P=${BAREMETAL_PREFIX:-arm-none-eabi-}
allowed='^(memcpy|memmove|memset|memcmp|(sqrt|cbrt|exp|exp2|expm1|log|log2|log10|log1p|pow|sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|hypot|floor|ceil|round|lround|llround|rint|lrint|nearbyint|trunc|fabs|fmod|fmin|fmax|copysign|nextafter|ldexp|frexp|modf|scalbn)[fl]?|__aeabi_[a-z0-9_]+|__gnu_[a-z0-9_]+)$'
status=0
printf '%-12s %9s %6s %6s  %s\n' target .text .data .bss "C library functions used"
for dir in "$@"; do
  target=$(basename "$dir")
  read -r text data bss < <("${P}size" -t "$dir/libhome.a" | awk 'END {print $1, $2, $3}')
  defined=$("${P}nm" --defined-only "$dir/libhome.a" | awk 'NF == 3 {print $3}' | sort -u)
  used=$("${P}nm" -u "$dir/libhome.a" | awk 'NF == 2 {print $2}' | sort -u | comm -23 - <(echo "$defined"))
  printf '%-12s %9s %6s %6s  %s\n' "$target" "$text" "$data" "$bss" "$(echo $used)"
  if [ "$data" != 0 ] || [ "$bss" != 0 ]; then
    echo "baremetal: $target: .data $data / .bss $bss bytes: the library must have no writable globals"
    "${P}size" "$dir/libhome.a" | awk 'NR > 1 && ($2 || $3)'
    status=1
  fi
  other=$(echo "$used" | grep -Ev "$allowed" || true)
  if [ -n "$other" ]; then
    echo "baremetal: $target: calls outside the freestanding set (an OS dependency): $(echo $other)"
    status=1
  fi
  [ -s "$dir/firmware.elf" ] || { echo "baremetal: $target: firmware.elf not linked"; status=1; }
done
[ $status = 0 ] && echo "baremetal: no writable globals, no OS calls; firmware images link against newlib without system-call stubs"
exit $status
