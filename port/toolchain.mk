# Per-target compiler settings, chosen from CROSS_COMPILE (or the host compiler's target).
TARGET_TRIPLE := $(shell $(CC) -dumpmachine 2>/dev/null)
ifneq (,$(findstring arm-linux-gnueabihf,$(TARGET_TRIPLE)))
# Raspberry Pi 2 and later: ARMv7-A with NEON (Debian's armhf default has no NEON)
ARCH_FLAGS ?= -march=armv7-a -mfpu=neon -mfloat-abi=hard
QEMU_NAME := arm
QEMU_SYSROOT := /usr/arm-linux-gnueabihf
endif
ifneq (,$(findstring aarch64,$(TARGET_TRIPLE)))
ARCH_FLAGS ?=
QEMU_NAME := aarch64
QEMU_SYSROOT := /usr/aarch64-linux-gnu
endif
ARCH_FLAGS ?=
# x86-64: the AVX2 kernels get their own flags; the rest of the library stays at the SSE2 baseline
ifneq (,$(findstring x86_64,$(TARGET_TRIPLE)))
AVX2_FLAGS := -mavx2
endif
# Cross builds run their test binaries under qemu-user unless RUNNER is given: the emulator
# that is installed, qemu-user-static's (qemu-aarch64-static) before qemu-user's (qemu-aarch64).
# With neither, the goals that run target binaries stop here, naming the packages.
ifneq ($(QEMU_NAME),)
QEMU_FOUND := $(firstword $(foreach q,qemu-$(QEMU_NAME)-static qemu-$(QEMU_NAME),$(shell command -v $(q) 2> /dev/null)))
QEMU ?= $(if $(QEMU_FOUND),$(notdir $(QEMU_FOUND)) -L $(QEMU_SYSROOT))
endif
ifneq ($(CROSS_COMPILE),)
ifeq ($(origin RUNNER),undefined)
ifeq ($(strip $(QEMU)),)
ifneq ($(filter test demo golden bench-refine,$(MAKECMDGOALS)),)
$(error no emulator for $(TARGET_TRIPLE) binaries: neither qemu-$(QEMU_NAME)-static nor qemu-$(QEMU_NAME) is on PATH; apt-get install qemu-user-static (or qemu-user), or give RUNNER=)
endif
endif
RUNNER := $(QEMU)
endif
endif
RUNNER ?=
