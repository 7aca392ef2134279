# Front door. `make test` and `make demo` work on a fresh Debian 12 machine:
# each installs what is missing, builds, then does its job.
BUILD      ?= build
JOBS       ?= $(shell nproc)
# Blenders by name (tools/blenders.py: 3.4 is Debian's, 4.5, 5.0 and 5.2 are bpy from
# PyPI, installed into $(BUILD)/blenders on first use) or by path. BLENDER runs demo,
# scenes and bench (and is asked for the Python version to build for); `make test`
# runs all of tests/blender in each of BLENDERS (the oldest and the newest) and the
# package-level check (install each zip, solve, bake, compare with Cycles) in each of
# CHECK_BLENDERS, e.g. `make test BLENDERS=3.4 CHECK_BLENDERS=` for a quick run.
# NATIVE_PYTHONS: the CPythons (tools/cpython.py) tests/native runs in besides Debian's
# 3.11, each with the module built for it.
BLENDER    ?= 3.4
BLENDERS   ?= 3.4 5.2
CHECK_BLENDERS ?= 4.5 5.0
NATIVE_PYTHONS ?= 3.10 3.13
PYTHON     ?= /usr/bin/python3
SCENE      ?= office
CMAKE_ARGS ?=
# PORTABLE=ON: the shipped module is built for manylinux_2_28 with zig (its tools and
# static Embree and TBB built once into $(BUILD)/portable-deps, about 15 minutes the
# first time); OFF: a quick local GCC build with Debian's libraries bundled.
PORTABLE   ?= ON
MAKEFLAGS  += --no-print-directory
ifdef CI
CMAKE_ARGS += -DRADIOSITY_WERROR=ON
endif

.PHONY: all deps portable configure build test unit demo scenes package bench figures clean blenders validator \
        fuzz sanitize test-platforms

# The command that runs $(BLENDER), installing it first if it is a bpy not yet installed.
BLENDER_EXE = "$$($(PYTHON) tools/blenders.py install --build $(BUILD) $(BLENDER) >&2 && \
                  $(PYTHON) tools/blenders.py executable --build $(BUILD) $(BLENDER))"

all: build

deps:
	@bash .ci/install-deps.sh

# The module is built for the Python of $(BLENDER), so CMake asks that Blender.
$(BUILD)/CMakeCache.txt: | deps portable
	cmake -S . -B $(BUILD) -DBLENDER_EXECUTABLE="$$(command -v $(BLENDER_EXE))" \
	      -DRADIOSITY_PORTABLE=$(PORTABLE) $(CMAKE_ARGS)

configure: $(BUILD)/CMakeCache.txt

# The portable build's compiler and libraries (tools/portable_deps.py; a no-op once made).
portable: deps
ifeq ($(PORTABLE),ON)
	@$(PYTHON) tools/portable_deps.py --build $(BUILD)
endif

build: deps portable configure
	@cmake --build $(BUILD) -j $(JOBS)

# Unit tests (CTest), Python tests of the native module and the packages, and the
# headless Blender tests in each of $(BLENDERS), with one summary line at the end.
test: build package blenders validator
	@$(PYTHON) tests/run_tests.py --build $(BUILD) $(foreach b,$(BLENDERS),--blender $(b)) \
	    $(foreach b,$(CHECK_BLENDERS),--check-blender $(b)) $(foreach p,$(NATIVE_PYTHONS),--native-python $(p))

# Installs each bpy of $(BLENDERS) and $(CHECK_BLENDERS) that is missing (pinned; a no-op once there).
blenders:
	@$(PYTHON) tools/blenders.py install --build $(BUILD) $(BLENDERS) $(CHECK_BLENDERS)

# The Khronos glTF validator (npm, pinned in tools/gltf_validator.py) in $(BUILD)/node,
# for tests/blender/test_gltf_export.py (a no-op once there).
validator: deps
	@$(PYTHON) tools/gltf_validator.py install --build $(BUILD)

scenes: build
	@$(PYTHON) scenes/build_all.py --build $(BUILD) --blender $(BLENDER_EXE)

demo: build
	@$(PYTHON) scenes/demo.py --build $(BUILD) --blender $(BLENDER_EXE) --scene $(SCENE)

# The zip of each platform, one for every Blender (an extension in 4.2+, an add-on in 3.x; tools/package.py):
# Linux always; Windows and macOS where `make test-platforms` made their dependencies
# (their modules are brought up to date first: tools/cross_build.py --if-deps).
package: build
	@$(PYTHON) tools/cross_build.py --build $(BUILD) --jobs $(JOBS) --if-deps
	@$(PYTHON) tools/package.py --build $(BUILD)

# The Windows and macOS zips and their tests, outside `make test` (fresh, about 20
# minutes per platform on two cores, README "Windows and macOS"): Wine and LLVM's tools
# from Debian; per platform zig's runtime, Embree and oneTBB (once, into $(BUILD)/cross),
# its modules for each CPython (tools/cross_build.py; macOS ones signed with rcodesign,
# built once with cargo), the zips, then tests/platforms: each module's imports, exports
# and signature, and the Windows ones run under Wine (tests/native; Windows bpy 4.5
# installing the zip through both installers, solving and baking).
test-platforms: build
	@bash .ci/install-deps.sh platforms
	@$(PYTHON) tools/cross_build.py --build $(BUILD) --jobs $(JOBS)
	@$(PYTHON) tools/package.py --build $(BUILD) --require-all
	@$(PYTHON) tests/run_tests.py --build $(BUILD) --only-platforms

bench: build
	@$(PYTHON) bench/run_bench.py --build $(BUILD) --blender $(BLENDER_EXE) $(if $(QUICK),--quick,)

# Section 4.3.1 of the source (Figures 22-25): F and |grad F| behind an occluder,
# as PNG images in $(BUILD)/figures (FIGURE_SIZE pixels square).
FIGURE_SIZE ?= 512
figures: deps configure
	@cmake --build $(BUILD) -j $(JOBS) --target visibility_figures
	@$(BUILD)/tools/visibility_figures $(BUILD)/figures $(FIGURE_SIZE)

# Issue 19's fuzzing campaign for FUZZ_SECONDS (tools/fuzz.py): the libFuzzer harnesses
# of native/fuzz and atheris over the Python API (clang 16 and atheris installed for it
# alone, into the system and $(BUILD)/fuzz/venv), then the slice's generators with new seeds.
FUZZ_SECONDS ?= 600
fuzz:
	@bash .ci/install-deps.sh fuzz
	@$(PYTHON) tools/fuzz.py --build $(BUILD) --seconds $(FUZZ_SECONDS) --jobs $(JOBS)

# The C++ unit tests and tests/native under AddressSanitizer and UndefinedBehaviorSanitizer,
# built into $(BUILD)/sanitize (tools/sanitize.py).
sanitize: deps
	@$(PYTHON) tools/sanitize.py --build $(BUILD) --jobs $(JOBS)

clean:
	rm -rf $(BUILD)
