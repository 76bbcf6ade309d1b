# Measurements: speed against OpenCV ORB and instruction counts (bench), the refinement's
# per-frame cost (bench-refine), the evaluation on real photographs (eval, eval-trust).
# make bench: libhome vs OpenCV ORB in one run (needs g++ and Debian's libopencv-dev), plus
# instruction counts per backend (valgrind callgrind) when valgrind is present.
BENCH_BIN := $(BUILD)/bin/home-bench
OPENCV_FLAGS = $(shell pkg-config --cflags --libs opencv4 2>/dev/null)

$(BENCH_BIN): bench/bench_vs_orb.cpp $(SUPPORT_OBJ) $(LIB) include/home.h
	@mkdir -p $(dir $@)
	@if [ -z "$(OPENCV_FLAGS)" ]; then echo "bench: needs libopencv-dev (apt-get install libopencv-dev g++ pkg-config)"; exit 1; fi
	$(CXX) -std=c++17 -O2 -Iinclude -Iexamples -Itests/support bench/bench_vs_orb.cpp $(SUPPORT_OBJ) $(LIB) -o $@ $(OPENCV_FLAGS) -lm

.PHONY: bench
bench: $(BENCH_BIN) $(BUILD)/bin/home-register $(BUILD)/bin/home-make-pair
	$(BENCH_BIN) $(BENCH_RUNS)
	BUILD=$(BUILD) bash bench/instructions.sh

# make bench-refine: per-frame cost of the refinement (video case) next to HOME alone
REFINE_BENCH := $(BUILD)/bin/home-bench-refine
BINS += $(REFINE_BENCH)
$(REFINE_BENCH): $(BUILD)/obj/bench/refine/bench_refine.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)
.PHONY: bench-refine
bench-refine: $(REFINE_BENCH)
	$(RUNNER) $(REFINE_BENCH) --frames 40
	$(RUNNER) $(REFINE_BENCH) --frames 40 --kind weak

# Evaluation against ORB, AKAZE and LSD/LBD on real photographs (bench/eval, Python 3).
#   make eval        full run: regenerates bench/eval/results.md and its plots
#   make eval-quick  the CI subset: report in $(EVAL_CACHE)/quick/results.md
#   make eval-trust        can `ok` be trusted (docs/trust.md)? tuning set vs test set, still
#                          pairs, consecutive frames, static camera, and the sealed set's
#                          static clips; rewrites bench/eval/trust_results.md,
#                          trust_results.json.gz and trust_*.png
#   make eval-trust-quick  its CI subset, tuning and test sets only (report in
#                          $(EVAL_CACHE)/trust-quick/; fails only when the harness breaks,
#                          never on the numbers)
# Photographs come from Debian packages (apt-get download) into $(EVAL_CACHE).
EVAL_CACHE ?= $(BUILD)/eval-cache
EVAL_JOBS ?= 2
EVAL_PYTHON ?= python3
EVAL_PIP := numpy 'opencv-contrib-python-headless<5' matplotlib
EVAL_RUN = $(EVAL_PYTHON) bench/eval/run.py --home $(BUILD)/bin/home-register \
	--cache $(EVAL_CACHE) --jobs $(EVAL_JOBS)

.PHONY: eval eval-quick eval-deps eval-trust eval-trust-quick
eval-deps:
	@$(EVAL_PYTHON) -c 'import numpy, matplotlib, cv2; cv2.line_descriptor.LSDDetector_createLSDDetector' 2>/dev/null \
	|| $(EVAL_PYTHON) -m pip install --quiet $(EVAL_PIP) \
	|| $(EVAL_PYTHON) -m pip install --quiet --break-system-packages $(EVAL_PIP)

eval: $(BUILD)/bin/home-register eval-deps
	$(EVAL_RUN)

eval-quick: $(BUILD)/bin/home-register eval-deps
	$(EVAL_RUN) --quick

# EVAL_TRUST_ARGS: more trust.py options, e.g. --sets test --suites static (sets: tuning,
#   test, sealed; sealed has static clips only), or
#   --extra-args "--refine-trust 40" (passed to every home-register run)
EVAL_TRUST_ARGS ?=
EVAL_TRUST = $(EVAL_PYTHON) bench/eval/trust.py --home $(BUILD)/bin/home-register \
	--stab $(BUILD)/bin/home-stab --cache $(EVAL_CACHE) --jobs $(EVAL_JOBS) $(EVAL_TRUST_ARGS)

eval-trust: $(BUILD)/bin/home-register $(BUILD)/bin/home-stab eval-deps
	$(EVAL_TRUST)

eval-trust-quick: $(BUILD)/bin/home-register $(BUILD)/bin/home-stab eval-deps
	$(EVAL_TRUST) --quick

# make bench-stab-realworld: home-stab against vidstab and deshake on the real-world set
# (bench/stab/realworld.py: rendered clips with cuts, fades, occluders, exposure steps, codecs,
# zoom and pans, and ViSP's real sequences; per-clip table in
# $(BUILD)/bench-stab-realworld/results.md). Needs ffmpeg with vid.stab; about 45 min on 2 cores.
# BENCH_STAB_ARGS: more realworld.py options, e.g. --set tuning, --quick, --clips cuts_test,
#   --stab-args "--lookahead 10"
BENCH_STAB_ARGS ?=
.PHONY: bench-stab-realworld
bench-stab-realworld: $(BUILD)/bin/home-stab $(BUILD)/bin/home-stab-clip eval-deps
	$(EVAL_PYTHON) bench/stab/realworld.py --build $(BUILD) --cache $(EVAL_CACHE) $(BENCH_STAB_ARGS)

# make bench-arm: executed aarch64 and armv7 (NEON) instructions per stage and per frame, for
# the video registration (home-arm-frames) and the stabiliser (home-stab), counted by a qemu
# TCG plugin (bench/arm/insn_count.c), with Cortex-A72/A76 time estimates from llvm-mca on the
# hottest blocks (bench/arm/report.py), and the working set per frame against a Pi 4's L2
# (aarch64; WORKING_SET=0 skips it). Needs qemu-user (the dynamically linked qemu-aarch64 and
# qemu-arm: static ones cannot load plugins), the two cross compilers, llvm and apt-get source
# access for qemu's plugin header (bench/arm/qemu_plugin_h.sh); about 9 minutes on 2 cores.
# BENCH_ARM_SIZES, BENCH_ARM_ARCHES narrow the run; docs/speed.md "ARM instruction counts" has
# the method and the numbers.
ARM_FRAMES := $(BUILD)/bin/home-arm-frames
BINS += $(ARM_FRAMES)
$(ARM_FRAMES): $(BUILD)/obj/bench/arm/frames.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)
BENCH_ARM_SIZES ?= 640x360 1280x720 1920x1080
BENCH_ARM_ARCHES ?= aarch64 armv7
.PHONY: bench-arm
bench-arm: $(BUILD)/bin/home-stab-clip
	BUILD=$(BUILD) SIZES="$(BENCH_ARM_SIZES)" ARCHES="$(BENCH_ARM_ARCHES)" bash bench/arm/count.sh
