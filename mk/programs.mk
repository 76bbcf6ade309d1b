# Programs on the library (examples/): home-register, home-make-pair, the stabiliser's home-stab
# and home-stab-clip, the capture examples eis-v4l2 / eis-libcamera when their dependencies are
# present, and the refinement's and the warp's bench tools.
# the scene and clip generators are test fixtures (tests/support/), which the pair and clip tools
# and the benches share
SUPPORT_OBJ := $(BUILD)/obj/examples/pgm.o $(BUILD)/obj/tests/support/synth.o
STAB_SUPPORT := $(BUILD)/obj/examples/y4m.o $(BUILD)/obj/examples/stab_png.o \
	$(BUILD)/obj/tests/support/stab_clip.o $(SUPPORT_OBJ)
BINS += $(BUILD)/bin/home-register $(BUILD)/bin/home-make-pair $(BUILD)/bin/home-stab \
	$(BUILD)/bin/home-stab-clip $(BUILD)/bin/home-refine-pair $(BUILD)/bin/home-warp-bands

$(BUILD)/obj/examples/%.o: examples/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) -c $< -o $@

$(BUILD)/obj/bench/%.o: bench/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) -c $< -o $@

$(BUILD)/bin/home-register: $(BUILD)/obj/examples/home-register.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-make-pair: $(BUILD)/obj/examples/make-pair.o $(SUPPORT_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-stab: $(BUILD)/obj/examples/home-stab.o $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) -pthread

$(BUILD)/bin/home-stab-clip: $(BUILD)/obj/examples/stab-make-clip.o $(STAB_SUPPORT)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# refines any estimate (bench/refine/refine_eval.py uses it for ORB + refinement)
$(BUILD)/bin/home-refine-pair: $(BUILD)/obj/bench/refine/refine-pair.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# the warp split across threads in bands (home_stab_warp_rows), against one thread: bench only
$(BUILD)/bin/home-warp-bands: $(BUILD)/obj/bench/stab/warp_bands.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) -pthread

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

$(BUILD)/obj/examples/eis-v4l2.o: examples/eis-v4l2.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) $(if $(filter 1,$(STAB_HAVE_SDL2)),-DHAVE_SDL2 $(shell $(PKG_CONFIG) --cflags sdl2)) -c $< -o $@

$(BUILD)/bin/eis-v4l2: $(BUILD)/obj/examples/eis-v4l2.o $(BUILD)/obj/examples/eis_common.o $(BUILD)/obj/examples/eis_pool.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) $(if $(filter 1,$(STAB_HAVE_SDL2)),$(shell $(PKG_CONFIG) --libs sdl2)) -pthread

$(BUILD)/bin/eis-libcamera: examples/eis-libcamera.cpp examples/eis_common.h examples/eis_pool.h $(BUILD)/obj/examples/eis_common.o $(BUILD)/obj/examples/eis_pool.o include/home_stab.h include/home.h $(LIB)
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror -Iinclude $(ARCH_FLAGS) $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer) \
		-Iexamples $(shell $(PKG_CONFIG) --cflags libcamera) $< $(BUILD)/obj/examples/eis_common.o $(BUILD)/obj/examples/eis_pool.o $(LIB) -o $@ $(LDFLAGS_APP) $(shell $(PKG_CONFIG) --libs libcamera) -pthread
