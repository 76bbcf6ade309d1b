# The library: src/ (the stages) on port/ (the kernels and the SIMD resolver). port/ files are
# named <stage>_<isa>.c; the ISA's flags come from the name (one pattern rule each), the rest of
# the library stays at the target's baseline.
LIB_SRC := $(wildcard src/*.c) $(wildcard port/*.c)
LIB_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC))

$(BUILD)/obj/src/%.o: src/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_LIB) $(DEPFLAGS) -c $< -o $@

$(BUILD)/obj/port/%.o: port/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_LIB) $(DEPFLAGS) -c $< -o $@

# x86-64: used only when the CPU reports AVX2 (port/dispatch.c)
$(BUILD)/obj/port/%_avx2.o: CFLAGS_LIB += $(AVX2_FLAGS)

# The Hough transform's per-theta loops (J from the line sums, the lines' end pixels), the
# refinement's residual bins, the descriptors' radial profiles and J's statistics (four lanes)
# are plain element-wise loops that -O2's cheapest vectoriser leaves scalar. Element-wise IEEE
# operations in C99 mode (no contraction, no reassociation), so bit-identical output.
# The line fit (port/line_fit.h) works on four matches per step in separate lanes, element-wise
# too; its sqrt vectorises only without errno (-fno-math-errno: same IEEE square roots).
# (The bare-metal build, mk/baremetal.mk, gives the same files the same flags.)
LIB_VECTORISE := src/hough.c $(wildcard src/refine*.c) src/describe.c src/pipeline.c src/stab_cut.c
LIB_VECTORISE_NOERRNO := src/homography.c $(wildcard port/line_fit_*.c)
$(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_VECTORISE)): CFLAGS_LIB += -ftree-vectorize
$(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_VECTORISE_NOERRNO)): CFLAGS_LIB += -ftree-vectorize -fno-math-errno

$(LIB): $(LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	$(AR) rcs $@ $^
