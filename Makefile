# bims: the two commands of the README (make demo, make test) and friends.
# Each target installs what is missing first, so a fresh Debian machine needs
# nothing else.

BUILD_DIR ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=
# Build trees made here use Ninja and a unity build (CMake joins ~8 sources
# of a target into one compile: the MRPT/Eigen/OpenCV headers and templates
# are parsed and instantiated once per batch, not per file). Both cut a
# clean build by about 40% (docs/journal/build-and-ci.md, "Build time"); UNITY=OFF gives
# one compile per file (a change then rebuilds only its own file).
GENERATOR ?= Ninja
UNITY ?= ON
TREE_ARGS = -G "$(GENERATOR)" -DCMAKE_UNITY_BUILD=$(UNITY)
# On CI (CI=true) a compiler warning is an error (BIMS_WERROR).
ifeq ($(CI),true)
TREE_ARGS += -DBIMS_WERROR=ON
endif

.PHONY: all deps configure build test test-sanitize demo bench fuzz format format-check clean

all: build

deps:
	@./scripts/install-deps.sh

configure: deps
	@if [ ! -f $(BUILD_DIR)/CMakeCache.txt ]; then \
	  cmake -S . -B $(BUILD_DIR) $(TREE_ARGS) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS); \
	fi

build: configure
	cmake --build $(BUILD_DIR) -j$(JOBS)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j$(JOBS) --timeout 900

# The suite again, built with AddressSanitizer + UndefinedBehaviorSanitizer
# (GUI and benchmarks off) in its own folder; any finding or leak fails it.
# LSan suppressions: tests/lsan.supp (MRPT-internal leaks only, each named).
SAN_BUILD_DIR ?= build-sanitize
# Left out of the sanitizer run (each runs in make test): the tests of the
# programs' command lines, sweeps and the installed package (labels cli,
# sweep, package: process plumbing, no code of their own); the whole-program
# runs on recordings (e2e), the simulator (sim), the replay viewer (viewer)
# and the live grabber (grab) and ROS 2 node (ros2: whole programs over DDS
# on a private loopback), whose code the other labels' tests run under
# the sanitizers on smaller inputs (the readers, the stages one by one, the
# pipeline with its threads: test_pipeline_stages); and the two longest
# equivalence tests left (1-1.5 min each under the sanitizers). The CI run
# has to stay under 30 min. Its tree does not build the test programs of
# those labels, nor the programs only they run (BIMS_SKIP_TEST_LABELS).
SAN_SKIP_LABELS = cli;sweep;package;e2e;sim;viewer;grab;ros2
SAN_EXCLUDE_LABELS = ^($(subst ;,|,$(SAN_SKIP_LABELS)))$$
# Its tree runs each test program as SAN_SHARDS processes (GoogleTest's
# sharding, BIMS_TEST_SHARDS), not one per case: starting a sanitized
# process costs ~0.9 s (docs/journal/build-and-ci.md, "CI time"). The cases
# left out are then a GoogleTest filter.
SAN_SHARDS ?= 4
SAN_GTEST_FILTER = -Raycast.SameCellsBlocksAndOrderAsThePerCellWalk:Apps.HelpExitsCleanlyAndBadOptionsExitWithCodeTwo
test-sanitize: deps
	@if [ ! -f $(SAN_BUILD_DIR)/CMakeCache.txt ]; then \
	  cmake -S . -B $(SAN_BUILD_DIR) $(TREE_ARGS) -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-O1 -DBIMS_SANITIZE=address,undefined \
	    -DBIMS_BUILD_GUI=OFF -DBIMS_BUILD_BENCH=OFF -DBIMS_BUILD_PYTHON=OFF -DBIMS_SKIP_TEST_LABELS='$(SAN_SKIP_LABELS)' \
	    -DBIMS_TEST_SHARDS=$(SAN_SHARDS) \
	    $(CMAKE_ARGS); \
	fi
	cmake --build $(SAN_BUILD_DIR) -j$(JOBS)
	cd $(SAN_BUILD_DIR) && \
	  ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=0 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  GTEST_FILTER='$(SAN_GTEST_FILTER)' \
	  ctest --output-on-failure -j$(JOBS) --timeout 1800 \
	    -LE '$(SAN_EXCLUDE_LABELS)'

demo: build
	@./scripts/demo.sh $(BUILD_DIR)

bench: build
	@./scripts/bench.sh $(BUILD_DIR)

# make fuzz TARGET=rawlog|ini|tum|labels|image|stray|stray_capture|bag SECONDS=N (docs/fuzz.md)
fuzz:
	@./scripts/fuzz.sh $(TARGET) $(SECONDS)

FORMAT_SOURCES = find apps libs tests bench examples -name '*.cpp' -o -name '*.h' 2>/dev/null
format:
	@$(FORMAT_SOURCES) | xargs -r clang-format -i

# Fails naming each file and line that make format would change (.ci/run).
format-check: deps
	@$(FORMAT_SOURCES) | xargs -r clang-format --dry-run --Werror
	@echo "[format] every source file is formatted"

clean:
	rm -rf $(BUILD_DIR)
