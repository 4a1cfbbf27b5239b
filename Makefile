# Thin wrapper around CMake.  `make run`: set up, build, prepare the bunny,
# run the default scene (the bunny drop on the coarse bunny).  `make test`:
# set up, build, run every test.  `make bench`: time the fracture-mode step.
BUILD     ?= build
BUNNY_OBJ := /usr/share/glmark2/models/bunny.obj
MESHES    := $(BUILD)/meshes
JOBS      ?= 2

.PHONY: all deps build meshes run test test-sanitize bench bench-scaling install clean

all: build

deps:
	@sh tools/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

meshes: build
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny --target-tets 200000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_small --target-tets 15000

run: meshes
	$(BUILD)/cohfrac run scenes/bunny_drop.lua --mesh-dir $(MESHES) -o out/bunny_drop.h5
	/usr/bin/python3 tools/check_run.py out/bunny_drop.h5
	/usr/bin/python3 tools/check_physics.py out/bunny_drop.h5
	/usr/bin/python3 tools/check_geometry.py out/bunny_drop.h5
	$(BUILD)/cohfrac render out/bunny_drop.h5

# The fracture-mode step on the 203k-tet bunny against the memory floor, 1
# against 2 threads and against btSoftBody (docs/performance.md).
bench: meshes
	$(BUILD)/cohfrac bench --peer -m $(MESHES)

# Step time and memory per tet from 15k to 800k tets.
bench-scaling: meshes
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_50k --target-tets 50000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_800k --target-tets 800000
	$(BUILD)/cohfrac bench --scaling -m $(MESHES)

# The library, headers, program, pkg-config file and CMake package under PREFIX.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

test: build
	cd $(BUILD) && ctest --output-on-failure

# The fast tests (label unit) built with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/; any report fails them,
# including one from a `cohfrac` process a test runs.
SANITIZE_ENV := ASAN_OPTIONS=halt_on_error=1:abort_on_error=0:detect_leaks=1 \
                UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
test-sanitize: deps
	@cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOHFRAC_SANITIZE=ON >/dev/null
	@cmake --build build-sanitize -j $(JOBS)
	cd build-sanitize && $(SANITIZE_ENV) ctest -L unit --output-on-failure

clean:
	rm -rf $(BUILD) build-sanitize out
