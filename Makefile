# The README's two commands: `make demo` and `make test`. Both install missing Debian packages,
# configure and build in Release, then run. `make` alone builds build/oralfluor.
BUILD ?= build
JOBS  ?= $(shell nproc)
OFL   := $(BUILD)/oralfluor
DEMO_OUT ?= out/demo

.PHONY: all deps configure build demo test bench clean

all: build

deps:
	@./.ci/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release > $(BUILD).configure.log 2>&1 || { cat $(BUILD).configure.log; exit 1; }

build: configure
	cmake --build $(BUILD) -j $(JOBS)

demo: build
	./scenes/demo.sh $(OFL) $(DEMO_OUT)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 900

bench: build
	./benchmarks/run_all.sh $(BUILD)

clean:
	rm -rf $(BUILD)
