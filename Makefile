# Basalt's entry points. Every target installs what it needs first (scripts/setup.sh, a no-op
# when all packages are present), so each works on a fresh Debian 12 machine: `make run` the
# packages that building and running need (scripts/packages.txt), the others those and the test
# tools too (scripts/packages-test.txt).
#
#   make run        build the program only and play the default show (RUN_ARGS to change it)
#   make test       build everything and run every test tier this machine can run, with a summary
#   make install    install the program, its module, the unit, udev rule and example shows
#                   (DESTDIR=/some/root to stage them)
#   make package    the Debian package of the same files: build/basalt_VERSION_ARCH.deb
#   make bench      build and run the benchmarks, printing their figures
#   make lint       clang-format and clang-tidy, as CI checks them
#   make format     reformat the sources with clang-format
#   make sanitize   build with AddressSanitizer + UBSan and run the unit, contract, render, media, script and fuzz tiers (the two day-long soaks run in make test only)
#   make fuzz       build the libFuzzer targets with clang-19 and run each for FUZZ_SECONDS; prints
#                   each target's final cov:/ft: figures
#   make fuzz-coverage  line coverage of each fuzz target's parser files over its corpus (the
#                   seeds and what make fuzz added), with clang-19's source-based coverage
#   make vlab       build and run the virtual-lab tests (qemu with real kernel drivers) alone
#   make vlab-shell an interactive shell inside the virtual lab, with the build tree

BUILD ?= build
BUILD_TYPE ?= RelWithDebInfo
RUN_ARGS ?= --seconds 10 --record out/default_show.mp4
CMAKE_ARGS ?=
FUZZ_SECONDS ?= 60

.PHONY: all setup setup-test configure configure-run build build-run run install package test bench lint format \
	sanitize fuzz fuzz-coverage vlab vlab-shell clean

all: build

setup:
	@scripts/setup.sh

setup-test:
	@scripts/setup.sh --test

CONFIGURE = cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DBASALT_WERROR=ON

configure: setup-test
	@$(CONFIGURE) -DBASALT_BUILD_TESTS=ON $(CMAKE_ARGS) >/dev/null

# A build folder made by `make run` has no tests (their packages may be missing); one that has
# them keeps them.
configure-run: setup
	@$(CONFIGURE) $(if $(wildcard $(BUILD)/CMakeCache.txt),,-DBASALT_BUILD_TESTS=OFF) $(CMAKE_ARGS) >/dev/null

build: configure
	@cmake --build $(BUILD)

# The program and the OpenImageIO module it loads; nothing else.
build-run: configure-run
	@cmake --build $(BUILD) --target basalt

run: build-run
	$(BUILD)/basalt run $(RUN_ARGS)

install: build-run
	@cmake --install $(BUILD)

# cpack, not the build folder's own `package` target, which would build every test first.
package: build-run
	@cd $(BUILD) && cpack -G DEB

test: build
	@scripts/run-tests.sh $(BUILD)

bench: build
	@for b in $(BUILD)/tests/bench/basalt_*_bench; do echo "== $$b"; $$b || exit 1; done

lint: build
	@scripts/lint.sh $(BUILD)

format:
	@git ls-files -co --exclude-standard -- '*.cpp' '*.h' | grep -E '^(runtime|devices|media|render|kiosk|sim|app|tools|tests)/' | \
	  xargs clang-format-19 -i

sanitize: setup-test
	@cmake -S . -B $(BUILD)-sanitize -G Ninja -DCMAKE_BUILD_TYPE=Debug -DBASALT_WERROR=ON \
	  -DBASALT_SANITIZE=address,undefined -DBASALT_BENCH=OFF $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD)-sanitize
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  scripts/run-tests.sh $(BUILD)-sanitize -L 'unit|contract|render|script|fuzz|media' -E '^Soak\.'

fuzz: setup-test
	@scripts/fuzz.sh $(FUZZ_SECONDS)

fuzz-coverage: setup-test
	@scripts/fuzz-coverage.sh

vlab: build
	@scripts/run-tests.sh $(BUILD) -L vlab

vlab-shell: setup-test
	@tools/vlab/shell $(if $(wildcard $(BUILD)),--build $(BUILD))

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize build-fuzz build-fuzz-cov out
