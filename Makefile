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
SAN := $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer)
CFLAGS_LIB := -std=c99 $(OPT) -g $(WARN) -Iinclude -Iport -fno-common $(ARCH_FLAGS) $(SAN) $(CFLAGS)
CFLAGS_APP := -std=c99 $(OPT) -g $(WARN) -Iinclude -Iexamples -Itests/support $(ARCH_FLAGS) $(SAN) $(CFLAGS)
LDFLAGS_APP := $(if $(SANITIZE),-fsanitize=$(SANITIZE)) $(LDFLAGS) -lm
# every compile writes its header dependencies next to its object (read back at the end)
DEPFLAGS := -MMD -MP

# The layers add to these (mk/*.mk): BINS (built by `make`), TEST_BINS (run by `make test`, each
# prints "N passed, N failed" last).
LIB := $(BUILD)/lib/libhome.a
BINS :=
TEST_BINS :=

.DEFAULT_GOAL := all
.PHONY: all test demo golden install clean

# the library (lib), the programs on it (programs), the test binaries (tests), speed and
# accuracy measurements (bench), the hardening tools (analysis), the bare-metal build (baremetal),
# the GStreamer plugin (gst), libcamera's virtual camera and the rpicam-apps stage (libcamera)
include mk/lib.mk mk/programs.mk mk/tests.mk mk/bench.mk mk/analysis.mk mk/baremetal.mk \
	mk/gst.mk mk/libcamera.mk

all: $(LIB) $(BINS)

test: all
	BUILD=$(BUILD) NM="$(NM)" OBJDUMP="$(OBJDUMP)" RUNNER="$(RUNNER)" CC="$(CC)" TEST_BINS="$(TEST_BINS)" SANFLAGS="$(if $(SANITIZE),-fsanitize=$(SANITIZE))" bash tests/run.sh

golden: all
	RUNNER="$(RUNNER)" GOLDEN_TARGET="$$($(CC) -dumpmachine)" bash tests/golden/golden.sh $(BUILD) --update

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
	install -m 644 include/home.h include/home_limits.h include/home_stab.h $(DESTDIR)$(PREFIX)/include/
	install -m 644 $(LIB) $(DESTDIR)$(PREFIX)/lib/
	printf 'prefix=%s\nlibdir=$${prefix}/lib\nincludedir=$${prefix}/include\n\nName: home\nDescription: HOME Hough-space frame registration (allocation-free C99)\nVersion: %s\nLibs: -L$${libdir} -lhome -lm\nCflags: -I$${includedir}\n' \
		'$(PREFIX)' "$$(sed -n 's/^#define HOME_VERSION_STRING "\(.*\)"/\1/p' include/home.h)" \
		> $(DESTDIR)$(PREFIX)/lib/pkgconfig/home.pc

clean:
	rm -rf $(BUILD) build-*

-include $(shell find $(BUILD) -name '*.d' 2> /dev/null)
