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
$(LCV_EIS): examples/eis-libcamera.cpp examples/eis_common.h examples/eis_pool.h $(BUILD)/obj/examples/eis_common.o $(BUILD)/obj/examples/eis_pool.o include/home_stab.h include/home.h $(LIB) $(LCV)/VERSION
	@mkdir -p $(dir $@)
	export PKG_CONFIG_PATH=$(abspath $(LCV))/prefix/lib/pkgconfig; \
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror -Iinclude $(ARCH_FLAGS) -Iexamples \
		$$($(PKG_CONFIG) --cflags libcamera) $< $(BUILD)/obj/examples/eis_common.o $(BUILD)/obj/examples/eis_pool.o $(LIB) -o $@ $(LDFLAGS_APP) \
		$$($(PKG_CONFIG) --libs libcamera) -Wl,-rpath,$(abspath $(LCV))/prefix/lib -pthread

# The rpicam-apps post-processing stage home_eis (examples/rpicam/, docs/libcamera.md): built by
# `make rpicam-stage` (and by `make` when RPICAM_APPS_DIR is set) from an rpicam-apps source tree's
# headers - rpicam-apps is in no package registry, so nothing here builds it otherwise - with
# Boost's headers (libboost-dev) and the libcamera pkg-config finds (RPICAM_PKG_CONFIG_PATH puts
# another first, e.g. $(LCV)/prefix/lib/pkgconfig). It links the PIC build of the library
# (mk/gst.mk) and leaves rpicam-apps' symbols to rpicam-vid, which loads it.
RPICAM_APPS_DIR ?=
RPICAM_PKG_CONFIG_PATH ?=
RPICAM_STAGE := $(BUILD)/lib/rpicam-apps-postproc/home_eis.so
.PHONY: rpicam-stage
ifneq ($(RPICAM_APPS_DIR),)
BINS += $(RPICAM_STAGE)
endif
rpicam-stage: $(RPICAM_STAGE)

$(RPICAM_STAGE): examples/rpicam/home_eis_stage.cpp include/home_stab.h include/home.h $(GST_PIC_LIB)
	@if [ ! -f "$(RPICAM_APPS_DIR)/post_processing_stages/post_processing_stage.hpp" ]; then \
		echo "rpicam-stage: set RPICAM_APPS_DIR to an rpicam-apps source tree (git clone https://github.com/raspberrypi/rpicam-apps.git)"; exit 2; fi
	@mkdir -p $(dir $@)
	$(if $(RPICAM_PKG_CONFIG_PATH),export PKG_CONFIG_PATH=$(RPICAM_PKG_CONFIG_PATH);) \
	$(CXX) -std=c++17 $(OPT) -g -Wall -Wextra -Werror -fPIC -shared -Iinclude -I$(RPICAM_APPS_DIR) \
		$$($(PKG_CONFIG) --cflags libcamera) $< $(GST_PIC_LIB) -o $@ $(LDFLAGS) -lm
