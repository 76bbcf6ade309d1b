# Live electronic image stabilisation (issue 6): home-stab (Y4M), home-stab-clip (shaky clips with
# ground truth), eis-v4l2 / eis-libcamera when their dependencies are present, the stabiliser
# tests, and the fake V4L2 device (LD_PRELOAD shim) the capture loop is tested against.
STAB_SUPPORT := $(BUILD)/obj/examples/y4m.o $(BUILD)/obj/examples/stab_png.o $(BUILD)/obj/examples/stab_clip.o $(SUPPORT_OBJ)
BINS += $(BUILD)/bin/home-stab $(BUILD)/bin/home-stab-clip $(BUILD)/bin/home-stab-tests
TEST_BINS += $(BUILD)/bin/home-stab-tests

$(BUILD)/obj/src/stabilise.o $(BUILD)/obj/src/warp.o: include/home_stab.h src/stab_warp.h

$(BUILD)/bin/home-stab: $(BUILD)/obj/examples/home-stab.o $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

$(BUILD)/bin/home-stab-clip: $(BUILD)/obj/examples/stab-make-clip.o $(STAB_SUPPORT)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)

# tests/test_stab.c also lands in home-tests (tests/*.c), where it compiles to nothing.
$(BUILD)/obj/tests/stab/test_stab.o: tests/test_stab.c include/home_stab.h src/stab_warp.h $(wildcard tests/*.h examples/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) -Isrc -DHOME_STAB_TESTS -c $< -o $@

$(BUILD)/bin/home-stab-tests: $(BUILD)/obj/tests/stab/test_stab.o $(STAB_SUPPORT) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP)
