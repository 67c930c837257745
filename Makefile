# Thin wrapper over CMake presets. `make demo` and `make test` are the README's two commands.
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BIN := build/release/pointillist

.PHONY: setup models configure build demo test test-asan fuzz bench clean

setup:
	bash scripts/setup.sh

# The sample models (Stanford dragon, bunny, lion) go to ~/.cache/pointillist/models.
models: setup
	bash scripts/fetch-models.sh || echo "make: could not fetch the sample models; continuing without them"

configure: setup
	cmake --preset release >/dev/null

build: configure
	cmake --build --preset release -j $(JOBS)

demo: build models
	$(BIN) demo --out demo-out

test: build models
	ctest --preset release

test-asan: setup models
	cmake --preset asan >/dev/null
	cmake --build --preset asan -j $(JOBS)
	ctest --preset asan

# The libFuzzer harnesses (fuzz/README.md): clang 14 with ASan + UBSan in build/fuzz, then each
# harness for FUZZ_SECONDS on its corpus, FUZZ_PARALLEL at a time. A crash fails the target; the
# report and the reproducer (build/fuzz/findings/<harness>/) are printed.
FUZZ_SECONDS ?= 60
FUZZ_PARALLEL ?= 2
fuzz: setup
	cmake --preset fuzz >/dev/null
	cmake --build --preset fuzz -j $(JOBS)
	bash fuzz/run.sh -s $(FUZZ_SECONDS) -j $(FUZZ_PARALLEL) -b build/fuzz

bench: build models
	bash bench/run.sh

clean:
	rm -rf build demo-out
