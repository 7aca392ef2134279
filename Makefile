# Front door. `make test` and `make demo` work on a fresh Debian 12 machine:
# each installs what is missing, builds, then does its job.
BUILD      ?= build
JOBS       ?= $(shell nproc)
BLENDER    ?= blender
PYTHON     ?= /usr/bin/python3
SCENE      ?= office
CMAKE_ARGS ?=
MAKEFLAGS  += --no-print-directory
ifdef CI
CMAKE_ARGS += -DRADIOSITY_WERROR=ON
endif

.PHONY: all deps configure build test unit demo scenes package bench figures clean

all: build

deps:
	@bash .ci/install-deps.sh

# The module is built for the Python of $(BLENDER), so CMake asks that Blender.
$(BUILD)/CMakeCache.txt: | deps
	cmake -S . -B $(BUILD) -DBLENDER_EXECUTABLE="$$(command -v $(BLENDER))" $(CMAKE_ARGS)

configure: $(BUILD)/CMakeCache.txt

build: deps configure
	@cmake --build $(BUILD) -j $(JOBS)

# Unit tests (CTest), Python tests of the native module and headless Blender tests,
# with one summary line at the end.
test: build
	@$(PYTHON) tests/run_tests.py --build $(BUILD) --blender $(BLENDER)

scenes: build
	@$(PYTHON) scenes/build_all.py --build $(BUILD) --blender $(BLENDER)

demo: build
	@$(PYTHON) scenes/demo.py --build $(BUILD) --blender $(BLENDER) --scene $(SCENE)

package: build
	@cmake --build $(BUILD) --target package

bench: build
	@$(PYTHON) bench/run_bench.py --build $(BUILD) --blender $(BLENDER) $(if $(QUICK),--quick,)

# Section 4.3.1 of the source (Figures 22-25): F and |grad F| behind an occluder,
# as PNG images in $(BUILD)/figures (FIGURE_SIZE pixels square).
FIGURE_SIZE ?= 512
figures: deps configure
	@cmake --build $(BUILD) -j $(JOBS) --target visibility_figures
	@$(BUILD)/tools/visibility_figures $(BUILD)/figures $(FIGURE_SIZE)

clean:
	rm -rf $(BUILD)
