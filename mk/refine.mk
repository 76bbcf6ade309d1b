# Photometric refinement (issue 8): its test binary (run by `make test`) and the bench tool that
# refines any estimate (bench/refine/refine_eval.py uses it for ORB + refinement).
REFINE_TESTS := $(BUILD)/bin/home-refine-tests
REFINE_PAIR := $(BUILD)/bin/home-refine-pair
BINS += $(REFINE_TESTS) $(REFINE_PAIR)
TEST_BINS += $(REFINE_TESTS)
# `all` expands BINS before this file is read: name the targets explicitly
all: $(REFINE_TESTS) $(REFINE_PAIR)

$(REFINE_TESTS): $(BUILD)/obj/tests/test_refine.o $(BUILD)/obj/tests/test_runner.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/obj/bench/refine/%.o: bench/refine/%.c include/home.h $(wildcard examples/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -c $< -o $@

$(REFINE_PAIR): $(BUILD)/obj/bench/refine/refine-pair.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# port/refine_kernels.h is not in the generic object rules' prerequisites
$(patsubst src/%.c,$(BUILD)/obj/src/%.o,$(wildcard src/refine*.c)) $(BUILD)/obj/src/arena.o $(BUILD)/obj/src/pipeline.o $(BUILD)/obj/tests/test_refine.o: port/refine_kernels.h
$(patsubst port/%.c,$(BUILD)/obj/port/%.o,$(wildcard port/refine_*.c)): port/refine_kernels.h
$(BUILD)/obj/port/refine_avx2.o: CFLAGS_LIB += $(AVX2_FLAGS)

# make bench-refine: per-frame cost of the refinement (video case) next to HOME alone
REFINE_BENCH := $(BUILD)/bin/home-bench-refine
BINS += $(REFINE_BENCH)
all: $(REFINE_BENCH)
$(REFINE_BENCH): $(BUILD)/obj/bench/refine/bench_refine.o $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)
.PHONY: bench-refine
bench-refine: $(REFINE_BENCH)
	$(RUNNER) $(REFINE_BENCH) --frames 40
	$(RUNNER) $(REFINE_BENCH) --frames 40 --kind weak
$(patsubst src/%.c,$(BUILD)/obj/src/%.o,$(wildcard src/refine*.c)): src/refine_internal.h
