# Test binaries, each run by `make test` (tests/run.sh, which then runs tests/checks/*.sh):
# home-tests (stages, pipeline, kernels, trust), home-refine-tests, home-stab-tests,
# home-hardening-tests (bad inputs, refusals) and home-fuzz-replay (the fuzz corpus through the
# harnesses); fake_v4l2.so is the V4L2 device the capture loop is tested against.
RUNNER_OBJ := $(BUILD)/obj/tests/support/test_runner.o
TEST_OBJ := $(patsubst %,$(BUILD)/obj/tests/%.o,test_main test_stages test_pipeline test_backends test_trust) \
	$(RUNNER_OBJ)
HARD_TEST_OBJ := $(patsubst tests/%.c,$(BUILD)/obj/tests/%.o,$(wildcard tests/test_bad_input*.c))
HARD_TESTS := $(BUILD)/bin/home-hardening-tests
FUZZ_REPLAY := $(BUILD)/bin/home-fuzz-replay
FUZZ_TARGETS := api stab pgm y4m
FUZZ_REPLAY_OBJ := $(foreach t,$(FUZZ_TARGETS),$(BUILD)/obj/fuzz-replay/fuzz_$(t).o)
FUZZ_SUPPORT := $(SUPPORT_OBJ) $(BUILD)/obj/examples/y4m.o
TEST_BINS += $(BUILD)/bin/home-tests $(BUILD)/bin/home-refine-tests $(BUILD)/bin/home-stab-tests \
	$(HARD_TESTS) $(FUZZ_REPLAY)
BINS += $(TEST_BINS)

$(BUILD)/obj/tests/%.o: tests/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) -Isrc -Iport -c $< -o $@

$(BUILD)/bin/home-tests: $(TEST_OBJ) $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-refine-tests: $(BUILD)/obj/tests/test_refine.o $(RUNNER_OBJ) $(SUPPORT_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# its own object directory: the generic tests/ rule builds home-tests' objects
$(BUILD)/obj/tests/stab/test_stab.o: tests/test_stab.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) -Isrc -Iport -DHOME_STAB_TESTS -c $< -o $@

$(BUILD)/bin/home-stab-tests: $(BUILD)/obj/tests/stab/test_stab.o $(RUNNER_OBJ) $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(HARD_TESTS): $(HARD_TEST_OBJ) $(RUNNER_OBJ) $(FUZZ_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) -pthread

FUZZ_TARGET_LIST := $(foreach t,$(FUZZ_TARGETS),X($(t)))
$(BUILD)/obj/fuzz-replay/fuzz_%.o: tests/fuzz/fuzz_%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) -DLLVMFuzzerTestOneInput=fuzz_$*_one -c $< -o $@

$(BUILD)/obj/fuzz-replay/replay.o: tests/fuzz/replay.c $(MAKEFILE_LIST)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $(DEPFLAGS) '-DFUZZ_TARGETS(X)=$(FUZZ_TARGET_LIST)' -c $< -o $@

$(FUZZ_REPLAY): $(BUILD)/obj/fuzz-replay/replay.o $(FUZZ_REPLAY_OBJ) $(RUNNER_OBJ) $(FUZZ_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# the fake camera is test support: never sanitized (it is preloaded into sanitized programs)
$(BUILD)/lib/fake_v4l2.so: tests/fake_v4l2/fake_v4l2.c
	@mkdir -p $(dir $@)
	$(CC) -std=c99 -O2 -g $(WARN) -fPIC -shared $< -o $@ -ldl

