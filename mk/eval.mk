# Evaluation against ORB, AKAZE and LSD/LBD on real photographs (bench/eval, Python 3).
#   make eval        full run: regenerates bench/eval/results.md and its plots
#   make eval-quick  the CI subset: report in $(EVAL_CACHE)/quick/results.md
# Photographs come from Debian packages (apt-get download) into $(EVAL_CACHE).
EVAL_CACHE ?= $(BUILD)/eval-cache
EVAL_JOBS ?= 2
EVAL_PYTHON ?= python3
EVAL_PIP := numpy 'opencv-contrib-python-headless<5' matplotlib
EVAL_RUN = $(EVAL_PYTHON) bench/eval/run.py --home $(BUILD)/bin/home-register \
	--cache $(EVAL_CACHE) --jobs $(EVAL_JOBS)

.PHONY: eval eval-quick eval-deps
eval-deps:
	@$(EVAL_PYTHON) -c 'import numpy, matplotlib, cv2; cv2.line_descriptor.LSDDetector_createLSDDetector' 2>/dev/null \
	|| $(EVAL_PYTHON) -m pip install --quiet $(EVAL_PIP) \
	|| $(EVAL_PYTHON) -m pip install --quiet --break-system-packages $(EVAL_PIP)

eval: $(BUILD)/bin/home-register eval-deps
	$(EVAL_RUN)

eval-quick: $(BUILD)/bin/home-register eval-deps
	$(EVAL_RUN) --quick
