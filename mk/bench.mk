# make bench: libhome vs OpenCV ORB in one run (needs g++ and Debian's libopencv-dev), plus
# instruction counts per backend (valgrind callgrind) when valgrind is present.
CXX ?= $(CROSS_COMPILE)g++
BENCH_BIN := $(BUILD)/bin/home-bench
OPENCV_FLAGS = $(shell pkg-config --cflags --libs opencv4 2>/dev/null)

$(BENCH_BIN): bench/bench_vs_orb.cpp $(SUPPORT_OBJ) $(LIB) include/home.h
	@mkdir -p $(dir $@)
	@if [ -z "$(OPENCV_FLAGS)" ]; then echo "bench: needs libopencv-dev (apt-get install libopencv-dev g++ pkg-config)"; exit 1; fi
	$(CXX) -std=c++17 -O2 -Iinclude -Iexamples bench/bench_vs_orb.cpp $(SUPPORT_OBJ) $(LIB) -o $@ $(OPENCV_FLAGS) -lm

.PHONY: bench
bench: $(BENCH_BIN) $(BUILD)/bin/home-register $(BUILD)/bin/home-make-pair
	$(BENCH_BIN) $(BENCH_RUNS)
	BUILD=$(BUILD) bash bench/instructions.sh
