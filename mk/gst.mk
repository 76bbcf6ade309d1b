# The GStreamer plugin (examples/gst/): libgsthome.so with the homestab element, and its
# GstHarness tests (home-gst-tests, in TEST_BINS when gstreamer-check-1.0 is present). Built
# when GStreamer's development packages are installed, else named as skipped like the optional
# examples; `make install` then installs the plugin into GStreamer's plugin directory
# (GST_PLUGINDIR, from pkg-config; DESTDIR honoured).
#
# A shared object needs position-independent code, and libhome.a is built for executables
# (the compiler's default PIE code, whose calls to the library's own functions a shared object
# cannot relocate). The plugin links a second build of the library, $(GST_PIC_LIB), made by this
# Makefile's own library rules in $(BUILD)/pic with -fPIC added: the same per-file flags, the
# same bytes out. Neither it nor the plugin is sanitized (a sanitized plugin would need its
# runtime preloaded into gst-launch); the harness tests compile the element into a test binary,
# which is.
GST_PKGS := gstreamer-1.0 gstreamer-video-1.0 gstreamer-base-1.0
GST_HAVE := $(shell $(PKG_CONFIG) --exists $(GST_PKGS) 2> /dev/null && echo 1)
GST_HAVE_CHECK := $(shell $(PKG_CONFIG) --exists gstreamer-check-1.0 2> /dev/null && echo 1)
GST_PLUGIN := $(BUILD)/lib/gstreamer-1.0/libgsthome.so
GST_TESTS := $(BUILD)/bin/home-gst-tests
GST_PIC_LIB := $(BUILD)/pic/lib/libhome.a
GST_PLUGINDIR ?= $(shell $(PKG_CONFIG) --variable=pluginsdir gstreamer-1.0 2> /dev/null)
# GStreamer's and GLib's headers are not -pedantic clean: included as system headers
GST_CFLAGS = $(patsubst -I%,-isystem %,$(shell $(PKG_CONFIG) --cflags $(GST_PKGS) $(if $(GST_HAVE_CHECK),gstreamer-check-1.0)))
GST_LIBS = $(shell $(PKG_CONFIG) --libs $(GST_PKGS))
CFLAGS_GST = -std=gnu99 $(OPT) -g $(WARN) -Iinclude -Iexamples $(ARCH_FLAGS) $(GST_CFLAGS)
.PHONY: install-gst gst-force

GST_SKIPPED :=
ifeq ($(GST_HAVE),1)
BINS += $(GST_PLUGIN)
ifeq ($(GST_HAVE_CHECK),1)
# (BINS took TEST_BINS's value in mk/tests.mk, before this: named here too, so `make` builds it)
TEST_BINS += $(GST_TESTS)
BINS += $(GST_TESTS)
else
GST_SKIPPED += home-gst-tests (gstreamer-check-1.0 not found: apt-get install libgstreamer1.0-dev)
endif
install: install-gst
else
GST_SKIPPED += the GStreamer plugin (GStreamer not found: apt-get install libgstreamer1.0-dev libgstreamer-plugins-base1.0-dev)
endif
# (not again from the sub-make that builds the PIC library)
ifneq ($(strip $(GST_SKIPPED)),)
ifeq ($(GST_PIC_SUBMAKE),)
$(info gst: skipped: $(strip $(GST_SKIPPED)))
endif
endif

# the PIC library: always asked of the sub-make, which rebuilds only what changed (the plugin
# relinks only when the archive did); its log is shown when it fails
$(GST_PIC_LIB): gst-force
	@mkdir -p $(BUILD)/pic
	@$(MAKE) --no-print-directory BUILD=$(BUILD)/pic SANITIZE= CFLAGS="$(CFLAGS) -fPIC" GST_PIC_SUBMAKE=1 $@ \
		> $(BUILD)/pic/make.log 2>&1 || { cat $(BUILD)/pic/make.log; exit 1; }
gst-force:

$(BUILD)/obj/gst/%.o: examples/gst/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_GST) -fPIC $(CFLAGS) $(DEPFLAGS) -c $< -o $@

# the warp's worker pool, shared with the live examples
$(BUILD)/obj/gst/eis_pool.o: examples/eis_pool.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_GST) -fPIC $(CFLAGS) $(DEPFLAGS) -c $< -o $@

$(GST_PLUGIN): $(BUILD)/obj/gst/gsthomestab.o $(BUILD)/obj/gst/eis_pool.o $(GST_PIC_LIB)
	@mkdir -p $(dir $@)
	$(CC) -shared -Wl,--no-undefined -Wl,-z,defs $^ -o $@ $(LDFLAGS) $(GST_LIBS) -lm -pthread

# the element compiled in (registered as a static plugin), sanitized with the rest of the tests
$(BUILD)/obj/gst-static/gsthomestab.o: examples/gst/gsthomestab.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_GST) $(SAN) $(CFLAGS) $(DEPFLAGS) -DGST_PLUGIN_BUILD_STATIC -c $< -o $@

$(BUILD)/obj/gst-static/test_gst.o: tests/test_gst.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_GST) -Itests/support $(SAN) $(CFLAGS) $(DEPFLAGS) -c $< -o $@

$(BUILD)/obj/gst-static/eis_pool.o: examples/eis_pool.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_GST) $(SAN) $(CFLAGS) $(DEPFLAGS) -c $< -o $@

$(GST_TESTS): $(BUILD)/obj/gst-static/test_gst.o $(BUILD)/obj/gst-static/gsthomestab.o $(BUILD)/obj/gst-static/eis_pool.o $(RUNNER_OBJ) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_APP) $^ -o $@ $(LDFLAGS_APP) $(GST_LIBS) $(shell $(PKG_CONFIG) --libs gstreamer-check-1.0) -pthread

install-gst: $(GST_PLUGIN)
	@if [ -z "$(GST_PLUGINDIR)" ]; then echo "install-gst: no GStreamer plugin directory (pkg-config --variable=pluginsdir gstreamer-1.0)"; exit 1; fi
	install -d $(DESTDIR)$(GST_PLUGINDIR)
	install -m 755 $(GST_PLUGIN) $(DESTDIR)$(GST_PLUGINDIR)/
