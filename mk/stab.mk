# Live electronic image stabilisation (issue 6): home-stab (Y4M), home-stab-clip (shaky clips with
# ground truth), eis-v4l2 / eis-libcamera when their dependencies are present, the stabiliser
# tests, and the fake V4L2 device (LD_PRELOAD shim) the capture loop is tested against.
STAB_SUPPORT := $(BUILD)/obj/examples/y4m.o $(BUILD)/obj/examples/stab_png.o $(BUILD)/obj/examples/stab_clip.o $(SUPPORT_OBJ)
BINS += $(BUILD)/bin/home-stab $(BUILD)/bin/home-stab-clip $(BUILD)/bin/home-stab-tests
TEST_BINS += $(BUILD)/bin/home-stab-tests

$(BUILD)/obj/src/stabilise.o $(BUILD)/obj/src/stab_motion.o $(BUILD)/obj/src/stab_path.o $(BUILD)/obj/src/warp.o $(patsubst port/%.c,$(BUILD)/obj/port/%.o,$(wildcard port/stab_*.c)): include/home_stab.h port/stab_kernels.h port/stab_x86.h
$(BUILD)/obj/port/stab_avx2.o: CFLAGS_LIB += $(AVX2_FLAGS)

$(BUILD)/bin/home-stab: $(BUILD)/obj/examples/home-stab.o $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) -pthread

$(BUILD)/bin/home-stab-clip: $(BUILD)/obj/examples/stab-make-clip.o $(STAB_SUPPORT)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# its own object directory: the generic tests/ rule builds home-tests' objects
$(BUILD)/obj/tests/stab/test_stab.o: tests/test_stab.c include/home.h include/home_stab.h include/home_limits.h port/stab_kernels.h $(wildcard tests/*.h examples/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -Isrc -Iport -DHOME_STAB_TESTS -c $< -o $@

$(BUILD)/bin/home-stab-tests: $(BUILD)/obj/tests/stab/test_stab.o $(BUILD)/obj/tests/test_runner.o $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# --- optional examples: built when their dependency is present, else named as skipped -------
PKG_CONFIG ?= $(CROSS_COMPILE)pkg-config
ifeq ($(origin CXX),default)
CXX := $(CROSS_COMPILE)g++
endif
STAB_HAVE_V4L2 := $(shell printf '\043include <linux/videodev2.h>\n' | $(CC) -E -x c - > /dev/null 2>&1 && echo 1)
STAB_HAVE_SDL2 := $(shell $(PKG_CONFIG) --exists sdl2 2> /dev/null && echo 1)
STAB_HAVE_LIBCAMERA := $(shell $(PKG_CONFIG) --exists libcamera 2> /dev/null && command -v $(CXX) > /dev/null && echo 1)
STAB_SKIPPED :=
ifeq ($(STAB_HAVE_V4L2),1)
BINS += $(BUILD)/bin/eis-v4l2 $(BUILD)/lib/fake_v4l2.so
ifneq ($(STAB_HAVE_SDL2),1)
STAB_SKIPPED += eis-v4l2 window (SDL2 not found: apt-get install libsdl2-dev; built without it)
endif
else
STAB_SKIPPED += eis-v4l2 (no <linux/videodev2.h>: apt-get install linux-libc-dev)
endif
ifeq ($(STAB_HAVE_LIBCAMERA),1)
BINS += $(BUILD)/bin/eis-libcamera
else
STAB_SKIPPED += eis-libcamera (libcamera or a C++17 compiler not found: apt-get install libcamera-dev g++ pkg-config)
endif
ifneq ($(strip $(STAB_SKIPPED)),)
$(info stab: skipped: $(strip $(STAB_SKIPPED)))
endif

$(BUILD)/obj/examples/eis-v4l2.o: examples/eis-v4l2.c examples/eis_common.h include/home_stab.h include/home.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(if $(filter 1,$(STAB_HAVE_SDL2)),-DHAVE_SDL2 $(shell $(PKG_CONFIG) --cflags sdl2)) -c $< -o $@

$(BUILD)/bin/eis-v4l2: $(BUILD)/obj/examples/eis-v4l2.o $(BUILD)/obj/examples/eis_common.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) $(if $(filter 1,$(STAB_HAVE_SDL2)),$(shell $(PKG_CONFIG) --libs sdl2))

# the fake camera is test support: never sanitized (it is preloaded into sanitized programs)
$(BUILD)/lib/fake_v4l2.so: tests/fake_v4l2/fake_v4l2.c
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O2 -g $(WARN) -fPIC -shared $< -o $@ -ldl

$(BUILD)/bin/eis-libcamera: examples/eis-libcamera.cpp examples/eis_common.h $(BUILD)/obj/examples/eis_common.o include/home_stab.h include/home.h $(LIB)
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror -Iinclude $(ARCH_FLAGS) $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer) \
		-Iexamples $(shell $(PKG_CONFIG) --cflags libcamera) $< $(BUILD)/obj/examples/eis_common.o $(LIB) -o $@ $(LDFLAGS_APP) $(shell $(PKG_CONFIG) --libs libcamera) -pthread

# the stabiliser's header goes with the library
install: stab-install-header
.PHONY: stab-install-header
stab-install-header:
	install -d $(DESTDIR)$(PREFIX)/include
	install -m 644 include/home_stab.h $(DESTDIR)$(PREFIX)/include/

# the warp split across threads in bands (home_stab_warp_rows), against one thread: bench only
BINS += $(BUILD)/bin/home-warp-bands
$(BUILD)/bin/home-warp-bands: bench/stab/warp_bands.c $(LIB) include/home_stab.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $< $(LIB) -o $@ $(LDFLAGS_APP) -pthread
$(BUILD)/obj/src/stabilise.o $(BUILD)/obj/src/stab_motion.o $(BUILD)/obj/src/stab_path.o: src/stab_state.h
