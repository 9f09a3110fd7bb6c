# The README's two commands: `make demo` and `make test`. Both install missing Debian packages,
# configure and build in Release, then run. `make` alone builds build/oralfluor.
BUILD ?= build
JOBS  ?= $(shell nproc)
OFL   := $(BUILD)/oralfluor
DEMO_OUT ?= out/demo

.PHONY: all deps configure build demo test bench clean sanitize

all: build

deps:
	@./.ci/install-deps.sh

# Configured once: a configured tree re-runs CMake by itself when a CMakeLists.txt changes.
configure: deps
	@test -f $(BUILD)/Makefile || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	./scenes/demo.sh $(OFL) $(DEMO_OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900

bench: build
	./benchmarks/run_all.sh $(BUILD)

# AddressSanitizer + UndefinedBehaviorSanitizer build in build-asan/ of what the suite runs (the CLI,
# the test binary, the Python module; not the benchmark programs), then the whole suite. The heaviest
# tests do less work there (tests/sanitizer_scale.h). Timings: benchmarks/results.d/61_sanitize.md.
SANITIZE_TARGETS := oralfluor oralfluor_tests _oralfluor oralfluor_python_files
sanitize: deps
	@cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DOFL_SANITIZE=ON > build-asan.configure.log 2>&1 || { cat build-asan.configure.log; exit 1; }
	cmake --build build-asan -j $(JOBS) --target $(SANITIZE_TARGETS)
	cd build-asan && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	  ctest --output-on-failure -j $(JOBS) --timeout 1800

clean:
	rm -rf $(BUILD)
