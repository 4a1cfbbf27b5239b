# Thin wrapper around CMake.  `make run`: set up, build, prepare the bunny,
# run the default scene (a plaster bunny dropped on its side, 993 tets).  `make test`:
# set up, build, run every test.  `make bench`: time the fracture-mode step.
BUILD     ?= build
BUNNY_OBJ := /usr/share/glmark2/models/bunny.obj
# Prepared meshes: the program's default mesh directory (the XDG cache,
# src/mesh/include/cohfrac/surface.h cf_default_mesh_dir), so that `cohfrac run`
# finds them from anywhere without --mesh-dir.
XDG_CACHE := $(if $(filter /%,$(XDG_CACHE_HOME)),$(XDG_CACHE_HOME),$(HOME)/.cache)
MESHES    ?= $(or $(COHFRAC_MESH_DIR),$(XDG_CACHE)/cohfrac/meshes)
JOBS      ?= 2

.PHONY: all deps build build-fuzz meshes run figures test test-sanitize fuzz bench bench-scaling install clean

all: build

deps:
	@sh tools/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

meshes: build
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny --target-tets 200000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_small --target-tets 15000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_1k --target-tets 1000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_4k --target-tets 4000

run: meshes
	$(BUILD)/cohfrac run scenes/plaster_bunny_drop.lua --mesh-dir $(MESHES) -o out/plaster_bunny_drop.h5
	/usr/bin/python3 tests/checks/check_run.py out/plaster_bunny_drop.h5 --max-hull-error 0.7
	/usr/bin/python3 tests/checks/check_physics.py out/plaster_bunny_drop.h5
	/usr/bin/python3 tests/checks/check_geometry.py out/plaster_bunny_drop.h5
	$(BUILD)/cohfrac render out/plaster_bunny_drop.h5 --to 0.06 --slow-motion 30
	$(BUILD)/cohfrac export out/plaster_bunny_drop.h5 --slow-motion 30
	-$(BUILD)/cohfrac blender-setup

# The source chapter's fracture figures (Fig 6.3, 6.11-6.14) at their
# defaults with the strength seeds 1-3, checked against what the chapter's
# text says each shows: the table in docs/scenes.md and the sheet
# docs/images/figures.png (tools/figures.py; exit 1 while an outcome does
# not hold for every seed).
figures: meshes
	/usr/bin/python3 tools/figures.py $(BUILD)/cohfrac -m $(MESHES) -o $(BUILD)/figures -j $(JOBS) \
	    --md docs/scenes.md --sheet docs/images/figures.png

# The fracture-mode step on the 203k-tet bunny against the memory floor, 1
# against 2 threads and against btSoftBody (docs/performance.md); its last
# line goes to bench/results/<machine>.csv (bench/record.sh).
bench: meshes
	@{ $(BUILD)/cohfrac bench --peer -m $(MESHES); echo $$? > $(BUILD)/bench.rc; } | tee $(BUILD)/bench.txt
	@[ "$$(cat $(BUILD)/bench.rc)" = 0 ] && sh bench/record.sh $(BUILD)/bench.txt

# Step time and memory per tet from 15k to 800k tets.
bench-scaling: meshes
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_80k --target-tets 80000
	$(BUILD)/cohfrac mesh $(BUNNY_OBJ) -o $(MESHES)/bunny_800k --target-tets 800000
	$(BUILD)/cohfrac bench --scaling -m $(MESHES)

# The library, headers, program, pkg-config file and CMake package under PREFIX.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

# Set-up, as for run: Debian's Blender 3.4 imports glTF with its defaults.
test: build
	-$(BUILD)/cohfrac blender-setup
	cd $(BUILD) && ctest --output-on-failure

# The fast tests (label unit) built with AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/; any report fails them,
# including one from a `cohfrac` process a test runs.  Built without MPI,
# which also checks that the program builds and says what to do without it.
SANITIZE_ENV := ASAN_OPTIONS=halt_on_error=1:abort_on_error=0:detect_leaks=1 \
                UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
test-sanitize: deps
	@cmake -S . -B build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCOHFRAC_SANITIZE=ON \
	    -DCOHFRAC_MPI=OFF >/dev/null
	@cmake --build build-sanitize -j $(JOBS)
	cd build-sanitize && $(SANITIZE_ENV) ctest -L unit --output-on-failure
	@$(MAKE) --no-print-directory build-fuzz
	cd build-fuzz && $(SANITIZE_ENV) ctest -L fuzz --output-on-failure

# The libFuzzer harnesses (tests/fuzz, clang, ASan + UBSan) in build-fuzz/:
# `make fuzz` runs each for SECONDS (default 60); `make test-sanitize` runs
# them for 15 s each through ctest (label fuzz).
SECONDS ?= 60
FUZZERS := surface tetgen gmsh scene
build-fuzz: deps
	@CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	    -DCOHFRAC_SANITIZE=ON -DCOHFRAC_FUZZ=ON >/dev/null
	@cmake --build build-fuzz -j $(JOBS) --target $(addprefix fuzz_,$(FUZZERS)) \
	    > build-fuzz/build.log 2>&1 || { cat build-fuzz/build.log; exit 1; }
fuzz: build-fuzz
	@for h in $(FUZZERS); do mkdir -p build-fuzz/tests/fuzz/corpus_$$h; \
	    $(SANITIZE_ENV) build-fuzz/tests/fuzz/fuzz_$$h -max_total_time=$(SECONDS) -timeout=10 \
	    -rss_limit_mb=2048 -print_final_stats=1 build-fuzz/tests/fuzz/corpus_$$h \
	    tests/fuzz/corpus/$$h $$([ $$h = scene ] && echo scenes scenes/verification) 2>&1 | grep -E 'stat::number_of_executed_units|ERROR|SUMMARY|Done' \
	    | sed "s/^/fuzz_$$h: /" || exit 1; done

clean:
	rm -rf $(BUILD) build-sanitize build-fuzz out
