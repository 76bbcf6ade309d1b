# libcamera's virtual camera (a camera without a device, libcamera >= 0.4.0): `make
# libcamera-virtual` builds libcamera from Debian's source package with only the virtual pipeline
# handler into $(LCV)/prefix (tests/support/build-libcamera-virtual.sh: a few minutes once, then
# cached), and eis-libcamera against it into $(LCV)/bin (run path set: nothing to install).
# tests/checks/libcamera-virtual.sh runs that eis-libcamera when it exists. Not part of `all`:
# it downloads a source package, and Debian 12's libcamera-dev (0.0.3) has no virtual camera.
LCV := $(BUILD)/libcamera-virtual
LCV_EIS := $(LCV)/bin/eis-libcamera
.PHONY: libcamera-virtual libcamera-virtual-force

libcamera-virtual: $(LCV_EIS)
	@echo "libcamera $$(cat $(LCV)/VERSION) (virtual camera): $(LCV)/prefix; eis-libcamera on it: $(LCV_EIS)"

# the script decides whether its cached build is still good
$(LCV)/VERSION: libcamera-virtual-force
	bash tests/support/build-libcamera-virtual.sh $(LCV)
libcamera-virtual-force:

# pkg-config is asked in the recipe: the prefix exists only once the rule above ran
$(LCV_EIS): examples/eis-libcamera.cpp examples/eis_common.h $(BUILD)/obj/examples/eis_common.o include/home_stab.h include/home.h $(LIB) $(LCV)/VERSION
	@mkdir -p $(dir $@)
	export PKG_CONFIG_PATH=$(abspath $(LCV))/prefix/lib/pkgconfig; \
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror -Iinclude $(ARCH_FLAGS) -Iexamples \
		$$($(PKG_CONFIG) --cflags libcamera) $< $(BUILD)/obj/examples/eis_common.o $(LIB) -o $@ $(LDFLAGS_APP) \
		$$($(PKG_CONFIG) --libs libcamera) -Wl,-rpath,$(abspath $(LCV))/prefix/lib -pthread

