# make baremetal: the library for bare-metal ARM with arm-none-eabi-gcc (Debian's
# gcc-arm-none-eabi, newlib): every library source compiled for each target in
# BAREMETAL_TARGETS, an archive per target, its .text/.data/.bss (arm-none-eabi-size), the C
# library functions it calls, and a link of tests/baremetal/firmware.c against newlib without
# system-call stubs, so an OS dependency fails the build. -DHOME_NO_GETENV: without an
# environment the HOME_SIMD override is compiled out (the one OS service the hosted build uses).
# Report and checks: tests/baremetal/check.sh.
BAREMETAL_PREFIX ?= arm-none-eabi-
BAREMETAL_TARGETS ?= cortex-a53 cortex-m7
# Cortex-A53 in AArch32 with NEON (the NEON kernels compile), Cortex-M7 with its double FPU
BAREMETAL_FLAGS_cortex-a53 := -mcpu=cortex-a53 -marm -mfpu=neon-fp-armv8 -mfloat-abi=hard
BAREMETAL_FLAGS_cortex-m7 := -mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard
BAREMETAL_CFLAGS = -std=c99 $(OPT) $(WARN) -Iinclude -Iport -fno-common -DHOME_NO_GETENV
BAREMETAL_DIR := $(BUILD)/baremetal

# one object, archive and image per target: $(1) = the target
define BAREMETAL_RULES
$(BAREMETAL_DIR)/$(1)/%.o: %.c
	@mkdir -p $$(dir $$@)
	$(BAREMETAL_PREFIX)gcc $(BAREMETAL_CFLAGS) $(BAREMETAL_FLAGS_$(1)) \
		$$(if $$(filter $$<,$(LIB_VECTORISE)),-ftree-vectorize) \
		$$(if $$(filter $$<,$(LIB_VECTORISE_NOERRNO)),-ftree-vectorize -fno-math-errno) \
		$(DEPFLAGS) -c $$< -o $$@
$(BAREMETAL_DIR)/$(1)/libhome.a: $(patsubst %.c,$(BAREMETAL_DIR)/$(1)/%.o,$(LIB_SRC))
	rm -f $$@
	$(BAREMETAL_PREFIX)ar rcs $$@ $$^
$(BAREMETAL_DIR)/$(1)/firmware.elf: tests/baremetal/firmware.c $(BAREMETAL_DIR)/$(1)/libhome.a
	$(BAREMETAL_PREFIX)gcc $(BAREMETAL_CFLAGS) $(BAREMETAL_FLAGS_$(1)) -nostartfiles \
		-Wl,--entry=fw_main $$< $(BAREMETAL_DIR)/$(1)/libhome.a -lm -lc -lgcc -o $$@
endef
$(foreach t,$(BAREMETAL_TARGETS),$(eval $(call BAREMETAL_RULES,$(t))))

.PHONY: baremetal
baremetal:
	@command -v $(BAREMETAL_PREFIX)gcc > /dev/null || { echo "baremetal: $(BAREMETAL_PREFIX)gcc not found: apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi"; exit 1; }
	$(MAKE) --no-print-directory $(foreach t,$(BAREMETAL_TARGETS),$(BAREMETAL_DIR)/$(t)/libhome.a $(BAREMETAL_DIR)/$(t)/firmware.elf)
	@BAREMETAL_PREFIX=$(BAREMETAL_PREFIX) bash tests/baremetal/check.sh $(foreach t,$(BAREMETAL_TARGETS),$(BAREMETAL_DIR)/$(t))
