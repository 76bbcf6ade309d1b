# libhome build. `make` builds the library, the CLI and the tests; `make test` runs the suite;
# `make demo` registers a generated structured pair. Cross builds: make CROSS_COMPILE=aarch64-linux-gnu-
# `make golden` records the outputs the byte-for-byte test compares (tests/golden/) anew: only when
# a change of the output is meant.
CROSS_COMPILE ?=
ifeq ($(origin CC),default)
CC := $(CROSS_COMPILE)gcc
endif
ifeq ($(origin AR),default)
AR := $(CROSS_COMPILE)ar
endif
NM ?= $(CROSS_COMPILE)nm
OBJDUMP ?= $(CROSS_COMPILE)objdump
PREFIX ?= /usr/local
BUILD ?= build
SANITIZE ?=
OPT ?= -O2
# RUNNER: run target binaries through this (cross builds default to qemu-user, port/toolchain.mk).

WARN := -Wall -Wextra -Werror -pedantic
-include port/toolchain.mk
CFLAGS_LIB := -std=c99 $(OPT) -g $(WARN) -Iinclude -Iport -fno-common $(ARCH_FLAGS) $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer) $(CFLAGS)
CFLAGS_APP := -std=c99 $(OPT) -g $(WARN) -Iinclude -Iexamples $(ARCH_FLAGS) $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer) $(CFLAGS)
LDFLAGS_APP := $(if $(SANITIZE),-fsanitize=$(SANITIZE)) $(LDFLAGS) -lm

LIB_SRC := $(wildcard src/*.c) $(wildcard port/*.c)
LIB_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC))
# Feature areas add their own programs, test binaries and rules in mk/*.mk:
#   BINS += ...  (built by `make`), TEST_BINS += ... (run by `make test`, each prints
#   "N passed, N failed" last), LIB_OBJ += ... (extra library objects, e.g. port/ kernels).
LIB := $(BUILD)/lib/libhome.a
SUPPORT_OBJ := $(BUILD)/obj/examples/pgm.o $(BUILD)/obj/examples/synth.o
TEST_OBJ := $(patsubst %,$(BUILD)/obj/tests/%.o,test_main test_runner test_stages test_pipeline test_kernels test_trust)
BINS := $(BUILD)/bin/home-register $(BUILD)/bin/home-make-pair $(BUILD)/bin/home-tests
TEST_BINS := $(BUILD)/bin/home-tests

.PHONY: all test demo golden install clean
all: $(LIB) $(BINS)

-include $(sort $(wildcard mk/*.mk))
# prerequisites are expanded when read: name the BINS that mk/*.mk added
all: $(BINS)

$(BUILD)/obj/src/%.o: src/%.c include/home.h include/home_limits.h src/home_internal.h port/kernels.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_LIB) -c $< -o $@

# The Hough transform's per-theta loops (J from the line sums, the lines' end pixels), the
# refinement's residual bins, the descriptors' radial profiles and J's statistics (four lanes)
# are plain element-wise loops
# that -O2's cheapest vectoriser leaves scalar (0.4, 0.2 and 0.2 M instructions per video
# frame). Element-wise IEEE operations in C99
# mode (no contraction, no reassociation), so bit-identical output.
# The line fit (port/line_fit.h) works on four matches per step in separate lanes, element-wise
# too; its sqrt vectorises only without errno (-fno-math-errno: same IEEE square roots).
$(BUILD)/obj/src/hough.o $(BUILD)/obj/src/refine.o $(BUILD)/obj/src/describe.o $(BUILD)/obj/src/pipeline.o: CFLAGS_LIB += -ftree-vectorize
# port/line_fit_avx2.c is the same fit compiled with AVX2 (four lanes, one 256-bit operation).
$(BUILD)/obj/src/homography.o $(BUILD)/obj/port/line_fit_scalar.o: CFLAGS_LIB += -ftree-vectorize -fno-math-errno
$(BUILD)/obj/port/line_fit_avx2.o: CFLAGS_LIB += -ftree-vectorize -fno-math-errno $(AVX2_FLAGS)
$(BUILD)/obj/port/line_fit_scalar.o $(BUILD)/obj/port/line_fit_avx2.o: port/line_fit.h port/line_fit_kernels.h
$(BUILD)/obj/port/avx2.o: CFLAGS_LIB += $(AVX2_FLAGS)
$(BUILD)/obj/port/%.o: port/%.c include/home.h include/home_limits.h port/kernels.h
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_LIB) -c $< -o $@

$(BUILD)/obj/examples/%.o: examples/%.c include/home.h include/home_stab.h include/home_limits.h $(wildcard examples/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -c $< -o $@

$(BUILD)/obj/tests/%.o: tests/%.c include/home.h $(wildcard tests/*.h examples/*.h src/home_internal.h)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -Isrc -Iport -c $< -o $@

$(LIB): $(LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	$(AR) rcs $@ $^

$(BUILD)/bin/home-register: $(BUILD)/obj/examples/home-register.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-make-pair: $(BUILD)/obj/examples/make-pair.o $(SUPPORT_OBJ)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-tests: $(TEST_OBJ) $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

test: all
	BUILD=$(BUILD) NM="$(NM)" OBJDUMP="$(OBJDUMP)" RUNNER="$(RUNNER)" CC="$(CC)" TEST_BINS="$(TEST_BINS)" SANFLAGS="$(if $(SANITIZE),-fsanitize=$(SANITIZE))" bash tests/run.sh

golden: all
	RUNNER="$(RUNNER)" bash tests/golden/golden.sh $(BUILD) --update

# The stabilisation demo: a shaky clip of a structured, low-texture scene with known camera
# motion, stabilised by home-stab (10 frames of lookahead); side-by-side Y4M (original |
# stabilised, playable with ffplay/mpv/vlc) and a PNG plot of the raw and smoothed camera path,
# both written by the tools themselves. Then the registration of one generated pair.
demo: all
	@mkdir -p $(BUILD)/demo
	$(RUNNER) $(BUILD)/bin/home-stab-clip --scene structured --frames 120 --shake 4 --rot 0.4 --pan 80 --seed 3 $(BUILD)/demo/shaky.y4m $(BUILD)/demo/truth.csv
	$(RUNNER) $(BUILD)/bin/home-stab --lookahead 10 --side-by-side --csv $(BUILD)/demo/path.csv --plot $(BUILD)/demo/path.png $(BUILD)/demo/shaky.y4m $(BUILD)/demo/side_by_side.y4m
	@python3 bench/stab/demo_jitter.py $(BUILD)/demo/truth.csv $(BUILD)/demo/path.csv 640 360
	@echo "side by side (original | stabilised): $(BUILD)/demo/side_by_side.y4m"
	@echo "camera path, raw (red) and smoothed (blue): $(BUILD)/demo/path.png; per frame: $(BUILD)/demo/path.csv"
	$(RUNNER) $(BUILD)/bin/home-make-pair --p 25 --seed 7 $(BUILD)/demo/a.pgm $(BUILD)/demo/b.pgm > $(BUILD)/demo/truth.json
	@echo "true H:      $$(cat $(BUILD)/demo/truth.json)"
	@echo "home-register $(BUILD)/demo/a.pgm $(BUILD)/demo/b.pgm:"
	@$(RUNNER) $(BUILD)/bin/home-register --save-hough $(BUILD)/demo/hough_a.pgm $(BUILD)/demo/a.pgm $(BUILD)/demo/b.pgm | tee $(BUILD)/demo/result.json
	@python3 tests/corner_error.py $(BUILD)/demo/truth.json $(BUILD)/demo/result.json
	@echo "Hough image of A with its keypoints: $(BUILD)/demo/hough_a.pgm"

install: $(LIB)
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 include/home.h include/home_limits.h $(DESTDIR)$(PREFIX)/include/
	install -m 644 $(LIB) $(DESTDIR)$(PREFIX)/lib/
	printf 'prefix=%s\nlibdir=$${prefix}/lib\nincludedir=$${prefix}/include\n\nName: home\nDescription: HOME Hough-space frame registration (allocation-free C99)\nVersion: %s\nLibs: -L$${libdir} -lhome -lm\nCflags: -I$${includedir}\n' \
		'$(PREFIX)' "$$(sed -n 's/^#define HOME_VERSION_STRING "\(.*\)"/\1/p' include/home.h)" \
		> $(DESTDIR)$(PREFIX)/lib/pkgconfig/home.pc

clean:
	rm -rf $(BUILD) build-*
