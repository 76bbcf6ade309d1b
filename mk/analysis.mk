# Hardening tools (the bad-input and fuzz-replay test binaries are in mk/tests.mk):
#   make fuzz       build the libFuzzer harnesses with clang and fuzz each for FUZZ_SECONDS
#   make lint       cppcheck and gcc -fanalyzer over src/ and port/
#   make stack      worst-case stack of every public function (-fstack-usage call graph) <= 16 KiB
#   make valgrind   memcheck over the bad-input table, the fuzz corpus and small end-to-end runs

# --- libFuzzer ----------------------------------------------------------------------------
# The library and support objects are built by this Makefile's own rules in FUZZ_BUILD with
# clang, coverage instrumentation and the sanitizers; the harnesses link -fsanitize=fuzzer.
FUZZ_BUILD ?= build-fuzz
FUZZ_CC ?= clang
FUZZ_SANITIZE ?= address,undefined
FUZZ_SECONDS ?= 60
.PHONY: fuzz fuzz-build fuzz-bins lint stack valgrind

fuzz-build:
	$(MAKE) BUILD=$(FUZZ_BUILD) CC=$(FUZZ_CC) SANITIZE=$(FUZZ_SANITIZE) \
		CFLAGS="-fsanitize=fuzzer-no-link -fno-sanitize-recover=all" fuzz-bins

# The pixel loops (Hough transform, smoothing, gradients, extrema, descriptors, refinement and
# warp kernels) keep edge coverage and the sanitizers but not comparison tracing: trace-cmp's call
# on every loop test was 70% of an execution and only fed loop bounds and pixel values to the
# mutator. Validation and decisions (config.c, context.c, match.c, homography.c, stabilise.c) keep it;
# pipeline.c (the per-row detection callback) and lm.c (the solver's loops) were a further 10%.
FUZZ_NO_TRACE_CMP := $(wildcard port/*.c) src/hough.c src/smooth.c src/gradient.c src/extrema.c \
	src/describe.c $(wildcard src/refine*.c) src/warp.c src/pipeline.c src/lm.c
ifeq ($(BUILD),$(FUZZ_BUILD))
$(patsubst %.c,$(BUILD)/obj/%.o,$(FUZZ_NO_TRACE_CMP)): CFLAGS_LIB += -fno-sanitize-coverage=trace-cmp
endif

fuzz-bins: $(foreach t,$(FUZZ_TARGETS),$(BUILD)/fuzz/fuzz_$(t))

$(BUILD)/fuzz/fuzz_%: tests/fuzz/fuzz_%.c $(FUZZ_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -fsanitize=fuzzer $< $(FUZZ_SUPPORT) $(LIB) -o $@ $(LDFLAGS_APP)

# FUZZ_SECONDS per target, as many side by side as there are cores (FUZZ_TARGET=api picks one).
fuzz: fuzz-build
	FUZZ_BUILD=$(FUZZ_BUILD) FUZZ_SECONDS=$(FUZZ_SECONDS) bash tests/fuzz/run.sh $(or $(FUZZ_TARGET),$(FUZZ_TARGETS))

# --- static analysis ----------------------------------------------------------------------
LINT_SRC := $(wildcard src/*.c port/*.c port/*/*.c)
# ctuuninitvar in extrema.c: the heap probe sets only the two fields ranks_below() reads
LINT_SUPPRESS := --suppress=ctuuninitvar:src/extrema.c
# cppcheck over all files in one run (its checks cross files), gcc -fanalyzer file by file: with
# make -j, side by side
LINT_OBJ := $(patsubst %.c,$(BUILD)/lint/%.o,$(LINT_SRC))
.PHONY: lint-cppcheck FORCE
FORCE:
lint: lint-cppcheck $(LINT_OBJ)
	@echo "lint: cppcheck and gcc -fanalyzer clean on $(words $(LINT_SRC)) files"

lint-cppcheck:
	cppcheck --std=c99 --enable=warning,portability,performance --error-exitcode=1 --quiet \
		--inline-suppr $(LINT_SUPPRESS) -Iinclude -Isrc -Iport $(LINT_SRC)

$(BUILD)/lint/%.o: %.c FORCE
	@mkdir -p $(dir $@)
	gcc -std=c99 -O2 $(WARN) -Iinclude -Isrc -Iport -fanalyzer -Wno-analyzer-too-complex -c $< -o $@

# --- stack --------------------------------------------------------------------------------
STACK_BUILD ?= build-stack
STACK_LIMIT ?= 16384
stack:
	$(MAKE) BUILD=$(STACK_BUILD) CFLAGS="-fstack-usage -fcallgraph-info=su" $(STACK_BUILD)/lib/libhome.a
	python3 tests/checks/stack_usage.py --limit $(STACK_LIMIT) --lib $(STACK_BUILD)/lib/libhome.a \
		--objdump $(CROSS_COMPILE)objdump $(STACK_BUILD)/obj

# --- valgrind -----------------------------------------------------------------------------
# The bad-input table, the must-fail pairs, the layout/arena determinism runs, the fuzz seeds and
# regression inputs, and the CLI on a small pair and on bad input (its exit 2 path frees everything too). The
# painted-stack test is left out: memcheck flags reads of a finished thread's stack.
VALGRIND ?= valgrind --error-exitcode=1 --leak-check=full --errors-for-leak-kinds=all \
	--show-leak-kinds=all -q
VALGRIND_TESTS := bad_input_table refusals_leave_context_usable fails_constant_and_noise \
	fails_single_edge fails_unrelated_scenes output_independent_of_arena_and_layout
# The parts run side by side under make -j: the two long tests of the table (about 25 s each
# under memcheck) apart from the rest.
VALGRIND_PARTS := valgrind-table valgrind-unrelated valgrind-tests valgrind-replay valgrind-cli
.PHONY: $(VALGRIND_PARTS)
valgrind: $(VALGRIND_PARTS)
	@echo "valgrind: memcheck clean (0 errors, 0 leaks)"

$(VALGRIND_PARTS): all
valgrind-table:
	$(VALGRIND) $(HARD_TESTS) bad_input_table
valgrind-unrelated:
	$(VALGRIND) $(HARD_TESTS) fails_unrelated_scenes
valgrind-tests:
	$(VALGRIND) $(HARD_TESTS) $(filter-out bad_input_table fails_unrelated_scenes,$(VALGRIND_TESTS))
valgrind-replay:
	set -e; for t in $(FUZZ_TARGETS); do \
		$(VALGRIND) $(FUZZ_REPLAY) $$t $$(ls tests/fuzz/corpus/$$t/seed-* tests/fuzz/corpus/$$t/regress-* 2> /dev/null) > /dev/null; done
valgrind-cli:
	@mkdir -p $(BUILD)/valgrind
	$(BUILD)/bin/home-make-pair --width 160 --height 120 $(BUILD)/valgrind/a.pgm $(BUILD)/valgrind/b.pgm > /dev/null
	$(VALGRIND) $(BUILD)/bin/home-register $(BUILD)/valgrind/a.pgm $(BUILD)/valgrind/b.pgm
	head -c 1000 $(BUILD)/valgrind/a.pgm > $(BUILD)/valgrind/truncated.pgm
	$(VALGRIND) $(BUILD)/bin/home-register $(BUILD)/valgrind/truncated.pgm $(BUILD)/valgrind/b.pgm; \
		test $$? -eq 2
