# Per-target compiler settings, chosen from CROSS_COMPILE (or the host compiler's target).
TARGET_TRIPLE := $(shell $(CC) -dumpmachine 2>/dev/null)
ifneq (,$(findstring arm-linux-gnueabihf,$(TARGET_TRIPLE)))
# Raspberry Pi 2 and later: ARMv7-A with NEON (Debian's armhf default has no NEON)
ARCH_FLAGS ?= -march=armv7-a -mfpu=neon -mfloat-abi=hard
QEMU ?= qemu-arm-static -L /usr/arm-linux-gnueabihf
endif
ifneq (,$(findstring aarch64,$(TARGET_TRIPLE)))
ARCH_FLAGS ?=
QEMU ?= qemu-aarch64-static -L /usr/aarch64-linux-gnu
endif
ARCH_FLAGS ?=
# x86-64: the AVX2 kernels get their own flags; the rest of the library stays at the SSE2 baseline
ifneq (,$(findstring x86_64,$(TARGET_TRIPLE)))
AVX2_FLAGS := -mavx2
endif
# Cross builds run their test binaries under qemu-user unless RUNNER is given.
ifneq ($(CROSS_COMPILE),)
RUNNER ?= $(QEMU)
endif
RUNNER ?=
