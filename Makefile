# lmgi — build, dependencies, tests, demo, benchmarks.
#   make            build build/lmgi, build/liblmgi.a, build/liblmgi.so
#   make deps       install missing Debian packages (apt-get, non-interactive; fast when nothing is missing)
#   make test       deps + build + every test (cmocka), including the loader fuzz test under ASan
#   make test-asan  the whole suite built with AddressSanitizer + UndefinedBehaviorSanitizer
#   make demo       deps + the main job on a generated scene; pictures in demo/
#   make fuzz       100,000 structured inputs through load, photons and a frame under ASan + UBSan
#   make bench      timings (never part of the tests)
#   make tradeoff   what accuracy costs in time: the quick knob sweep on the generated Cornell box,
#                   build/tradeoff/report.html (TRADEOFF_SCENES, TRADEOFF_FLAGS: the full sweep)
#   make install    PREFIX=DIR (default /usr/local): lmgi.h (and lmgi_knobs.h), lmgi_tools.h, liblmgi.a/.so, lmgi, lmgi.pc
#   make scenes     regenerate scenes/ with tools/gen_scenes

CC      ?= gcc
CXX     ?= g++
BUILD   ?= build
OPT     ?= -O2 -g
# Instruction set: the build machine's own by default (AVX2/FMA where it has them: the photon tracer's
# own work is about a fifth cheaper, docs/photons.md). `make ARCH=` builds for the baseline of the
# architecture, for binaries that must run on other machines.
ARCH    ?= -march=native
SAN     ?=
WARN    := -Wall -Wextra -Werror
# The photon tracer's arithmetic may use fused multiply-adds (ISO C mode forbids contraction by default):
# a multiply and an add are one instruction, rounded once. Only there (and in the reference solver,
# src/reference, which traces with it): elsewhere code such as the atlas's edge functions relies on
# a * b - c * d being computed the same way whichever way round it is taken.
# Its square roots are single instructions, without the test for a negative argument that would set
# errno (nothing reads it).
TRACE_FP := -ffp-contract=fast -fno-math-errno
# Hidden visibility: liblmgi.so exports only what include/lmgi.h and lmgi_tools.h mark LMGI_API (the static library and
# the programs linked with it are unaffected).
VIS          := -fvisibility=hidden
CFLAGS_ALL   := -std=c11 $(OPT) $(ARCH) $(WARN) -fPIC $(VIS) -fopenmp -D_DEFAULT_SOURCE -Iinclude -I$(BUILD)/gen $(SAN) \
                $(CFLAGS)
CXXFLAGS_ALL := -std=c++17 $(OPT) $(ARCH) $(WARN) -fPIC $(VIS) -fvisibility-inlines-hidden -fopenmp -Iinclude \
                -I/usr/include/stb $(SAN) $(CXXFLAGS)
LIBS    := -ltinygltf -lstb -ltinyexr -lembree3 -lOpenMeshCore -lmeshoptimizer -ldraco -lwebp -lEGL -lgomp -lstdc++ -lm -lpthread
LDFLAGS_ALL := -fopenmp $(SAN) $(LDFLAGS)
# The command line's own (not the library's: lmgi.pc does not name it): cJSON for a shard's part.json
# and the edit scripts of --edits
CLI_LIBS := -lcjson
# lmgi view's window (GLFW) and its drawing (the window's own OpenGL; the library links neither)
VIEW_LIBS := -lglfw -lGL

# npm: Debian's, unless a node that brings its own is installed (NodeSource's nodejs conflicts with it)
NPM_DEB := $(if $(shell command -v npm 2>/dev/null),,npm)
DEB_PACKAGES := build-essential pkg-config libembree-dev libosmesa6-dev libopenmesh-dev libtinygltf-dev \
                nlohmann-json3-dev libstb-dev libtinyexr-dev libmeshoptimizer-dev libwebp-dev libcmocka-dev \
                libegl-dev libegl-mesa0 python3-matplotlib libgl-dev libx11-dev xvfb nodejs chromium \
                openmpi-bin libopenmpi-dev libcjson-dev libdraco-dev draco gltfpack libglfw3-dev xdotool \
                $(NPM_DEB)

LIB_C   := $(sort $(wildcard src/core/*.c src/scene/*.c src/charts/*.c src/trace/*.c src/reference/*.c \
                             src/photonmap/*.c src/gpu/*.c src/gpu/*/*.c src/update/*.c src/api/*.c))
LIB_CXX := $(sort $(wildcard src/scene/*.cpp src/charts/*.cpp))
CLI_C   := $(sort $(wildcard src/cli/*.c))
# The shaders: src/gpu's .glsl files, made into C strings at build time by tools/glsl_embed.c (one
# lm_glsl_NAME a file, declared in the generated glsl.h; docs/architecture.md, "Shaders")
GLSL    := $(sort $(wildcard src/gpu/*/glsl/*.glsl))
GLSL_C  := $(BUILD)/gen/glsl.c
LIB_OBJ := $(LIB_C:%.c=$(BUILD)/obj/%.o) $(LIB_CXX:%.cpp=$(BUILD)/obj/%.o) $(BUILD)/obj/gen/glsl.o
CLI_OBJ := $(CLI_C:%.c=$(BUILD)/obj/%.o)
# lmgi-dev: the developer's commands that look inside the library (tools/dev/main.c), on the CLI's
# option parser and helpers
DEV_C   := $(sort $(wildcard tools/dev/*.c))
DEV_OBJ := $(DEV_C:%.c=$(BUILD)/obj/%.o) $(filter-out %/main.o,$(CLI_OBJ))
TEST_C  := $(sort $(wildcard tests/test_*.c))
TESTS   := $(TEST_C:tests/%.c=$(BUILD)/tests/%)
TEST_SUPPORT := $(BUILD)/obj/tests/support.o $(BUILD)/obj/tests/edit_room.o

.PHONY: all deps npm-deps test test-asan demo bench tradeoff scenes clean fuzz install install-files
.PRECIOUS: $(BUILD)/obj/%.o
.PHONY: FORCE
all: $(BUILD)/lmgi $(BUILD)/lmgi-dev $(BUILD)/liblmgi.a $(BUILD)/liblmgi.so

deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "install ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "deps: installing$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  $$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	fi

# The compile flags of this build directory: objects are rebuilt when OPT, ARCH, SAN or CFLAGS change.
$(BUILD)/flags: FORCE
	@mkdir -p $(dir $@)
	@echo '$(CFLAGS_ALL) | $(CXXFLAGS_ALL) | $(TRACE_FP)' > $@.new
	@if cmp -s $@.new $@; then rm $@.new; else mv $@.new $@; fi

$(BUILD)/obj/%.o: %.c $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -MMD -MP -c $< -o $@

$(BUILD)/obj/src/trace/%.o: CFLAGS_ALL += $(TRACE_FP)
# the reference solver was written in trace/ and traces with it: the same arithmetic, the same answers
$(BUILD)/obj/src/reference/%.o: CFLAGS_ALL += $(TRACE_FP)

# glsl_embed runs on every make (a .glsl removed must leave glsl.c too) but rewrites glsl.c and glsl.h
# only when their text changes: an edited shader rebuilds glsl.o alone, a shader added or removed the
# files that include glsl.h.
$(BUILD)/glsl_embed: tools/glsl_embed.c
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O2 $(WARN) -D_DEFAULT_SOURCE -o $@ $<
$(GLSL_C): $(BUILD)/glsl_embed FORCE
	@mkdir -p $(dir $@)
	@$(BUILD)/glsl_embed $(GLSL_C) $(BUILD)/gen/glsl.h $(GLSL)
$(BUILD)/gen/glsl.h: $(GLSL_C) ;
$(BUILD)/obj/gen/glsl.o: $(GLSL_C) $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS_ALL) -c $< -o $@
$(filter $(BUILD)/obj/src/gpu/%,$(LIB_OBJ)): | $(BUILD)/gen/glsl.h

$(BUILD)/obj/%.o: %.cpp $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS_ALL) -MMD -MP -c $< -o $@

$(BUILD)/liblmgi.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

# The version is include/lmgi.h's (LMGI_VERSION_*): the shared library's soname and lmgi.pc follow it
LMGI_VERSION = $(shell sed -n 's/^\#define LMGI_VERSION_\(MAJOR\|MINOR\|PATCH\) //p' include/lmgi.h | paste -sd.)
SONAME := liblmgi.so.$(firstword $(subst ., ,$(LMGI_VERSION)))
$(BUILD)/liblmgi.so: $(LIB_OBJ) src/api/lmgi.map
	$(CC) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=src/api/lmgi.map -o $@ $(LIB_OBJ) $(LDFLAGS_ALL) $(LIBS)

# make install PREFIX=DIR: the headers, both libraries, the lmgi command and lmgi.pc for pkg-config
# (`cc app.c $$(pkg-config --cflags --libs lmgi)`; add --static for liblmgi.a and its dependencies).
PREFIX ?= /usr/local
install: all install-files
# the copying alone, of what BUILD holds (test_examples installs each build's own libraries this way)
install-files:
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/bin
	install -m 644 include/lmgi.h include/lmgi_knobs.h include/lmgi_tools.h $(DESTDIR)$(PREFIX)/include/
	install -m 644 $(BUILD)/liblmgi.a $(DESTDIR)$(PREFIX)/lib/
	install -m 755 $(BUILD)/liblmgi.so $(DESTDIR)$(PREFIX)/lib/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(PREFIX)/lib/liblmgi.so
	install -m 755 $(BUILD)/lmgi $(DESTDIR)$(PREFIX)/bin/
	install -d $(DESTDIR)$(PREFIX)/share/lmgi
	install -m 644 tools/tradeoff_report.py $(DESTDIR)$(PREFIX)/share/lmgi/
	install -m 644 tools/engines/babylon_lmgi_lightmap.js $(DESTDIR)$(PREFIX)/share/lmgi/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(LMGI_VERSION)|' -e 's|@LIBS@|$(LIBS) -fopenmp|' lmgi.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/lmgi.pc

$(BUILD)/lmgi: $(CLI_OBJ) $(BUILD)/liblmgi.a
	$(CC) -o $@ $(CLI_OBJ) $(BUILD)/liblmgi.a $(LDFLAGS_ALL) $(LIBS) $(CLI_LIBS) $(VIEW_LIBS)

$(BUILD)/lmgi-dev: $(DEV_OBJ) $(BUILD)/liblmgi.a
	$(CC) -o $@ $(DEV_OBJ) $(BUILD)/liblmgi.a $(LDFLAGS_ALL) $(LIBS) $(CLI_LIBS) $(VIEW_LIBS)

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(TEST_SUPPORT) $(BUILD)/liblmgi.a
	@mkdir -p $(dir $@)
	$(CC) -o $@ $(filter %.o,$^) $(BUILD)/liblmgi.a $(LDFLAGS_ALL) $(LIBS) $(CLI_LIBS) -lcmocka

# The soak test plays the random edits of `lmgi bench --soak --random-edits` (src/cli/random_edits.c) and
# reads memory as it does.
$(BUILD)/tests/test_soak: $(BUILD)/obj/src/cli/random_edits.o $(BUILD)/obj/src/cli/resident_memory.o

# The per-channel criterion of `lmgi check` and `make bench` (src/cli/surface_error.c).
$(BUILD)/tests/test_surface_error: $(BUILD)/obj/src/cli/surface_error.o

# The frame checks load scenes as `lmgi run`, `lmgi check` and `lmgi bake` do (src/cli/run_options.c,
# bake_options.c) and judge a surface's channels as `lmgi check` does (surface_error.c).
$(BUILD)/tests/test_frame_check: $(BUILD)/obj/src/cli/run_options.o $(BUILD)/obj/src/cli/bake_options.o \
	$(BUILD)/obj/src/cli/surface_error.o

# The viewer's camera and views (src/cli/view_camera.c, view_maps.c)
$(BUILD)/tests/test_view_camera: $(BUILD)/obj/src/cli/view_camera.o
$(BUILD)/tests/test_view_maps: $(BUILD)/obj/src/cli/view_maps.o $(BUILD)/obj/src/cli/view_edit.o

# The GL guest test plays a GLX host on an X server: it alone links X and GLX (lmgi links neither).
$(BUILD)/tests/test_gl_guest: LIBS += -lGL -lX11 -ldl

# make mpi: build/lmgi-mpi, the lmgi command with `bake` spread over MPI ranks (docs/farm.md), where mpicc
# is found; the plain lmgi is built and behaves as without it. make test builds it when it can.
MPICC ?= mpicc
MPI_OBJ := $(BUILD)/obj/mpi/main.o $(BUILD)/obj/mpi/main_mpi.o
.PHONY: mpi
mpi: $(BUILD)/lmgi-mpi
$(BUILD)/obj/mpi/main.o: src/cli/main.c $(BUILD)/flags
	@command -v $(MPICC) > /dev/null || { echo "make mpi: $(MPICC) not found (Debian: apt-get install libopenmpi-dev openmpi-bin)"; exit 1; }
	@mkdir -p $(dir $@)
	$(MPICC) $(CFLAGS_ALL) -MMD -MP -Dmain=lm_cli_main -c $< -o $@
$(BUILD)/obj/mpi/main_mpi.o: src/cli/mpi/main_mpi.c $(BUILD)/flags
	@command -v $(MPICC) > /dev/null || { echo "make mpi: $(MPICC) not found (Debian: apt-get install libopenmpi-dev openmpi-bin)"; exit 1; }
	@mkdir -p $(dir $@)
	$(MPICC) $(CFLAGS_ALL) -MMD -MP -c $< -o $@
$(BUILD)/lmgi-mpi: $(MPI_OBJ) $(filter-out %/main.o,$(CLI_OBJ)) $(BUILD)/liblmgi.a
	$(MPICC) -o $@ $^ $(LDFLAGS_ALL) $(LIBS) $(CLI_LIBS) $(VIEW_LIBS)

# make bench-mpi: the MPI bake's scaling on 1, 2 and 4 ranks of this machine (docs/farm.md)
.PHONY: bench-mpi
bench-mpi: deps all $(BUILD)/lmgi-mpi
	@sh tools/bench_mpi.sh $(BUILD) scenes/two_rooms.glb --texels 20000
	@if [ -f ../shared/scenes/occlusion-room/room_lit.glb ]; then \
	  sh tools/bench_mpi.sh $(BUILD) ../shared/scenes/occlusion-room/room_lit.glb; fi

$(BUILD)/gen_scenes: tools/gen_scenes.c
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O2 $(WARN) -D_DEFAULT_SOURCE -o $@ $< -lm

# The fuzz tests always run under ASan + UBSan, whatever the main build is: fuzz_loader (byte mutations
# through the loader), fuzz_pipeline (structured mutations through load, photons and one frame) and
# fuzz_api (random call sequences with random values through the public API).
FUZZ_BUILD := build/asan
FUZZ_TESTS := $(FUZZ_BUILD)/tests/fuzz_loader $(FUZZ_BUILD)/tests/fuzz_pipeline $(FUZZ_BUILD)/tests/fuzz_api
# Their library is one make of its own (run once however many fuzz tests are linked at a time), and never
# beside the build of BUILD: under make test-asan both are build/asan (make test builds them one after
# the other)
.PHONY: fuzz-lib
fuzz-lib:
	@$(MAKE) --no-print-directory BUILD=$(FUZZ_BUILD) OPT="-O1 -g" \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" \
	  $(FUZZ_BUILD)/liblmgi.a $(FUZZ_BUILD)/obj/tests/support.o
$(FUZZ_BUILD)/tests/fuzz_%: fuzz-lib
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O1 -g $(WARN) -D_DEFAULT_SOURCE -Iinclude -fsanitize=address,undefined \
	  -o $@ tests/fuzz_$*.c $(FUZZ_BUILD)/obj/tests/support.o $(FUZZ_BUILD)/liblmgi.a \
	  -fsanitize=address,undefined -fopenmp $(LIBS) -lcmocka
FORCE:

# The engine tests' node packages (tests/test_engines.c): the Khronos glTF validator and Babylon.js, at
# the versions the tests were written against, installed once into build/npm for every build directory.
# Without npm or the registry the tests that need them skip and say so; make test goes on.
NPM_DIR      := build/npm
NPM_PACKAGES := gltf-validator@2.0.0-dev.3.10 babylonjs@9.28.0 babylonjs-loaders@9.28.0
npm-deps:
	@if [ "$$(cat $(NPM_DIR)/installed 2>/dev/null)" = "$(NPM_PACKAGES)" ]; then :; \
	elif ! command -v npm > /dev/null; then echo "npm-deps: npm is missing: the engine tests will skip"; \
	elif mkdir -p $(NPM_DIR) && npm install --prefix $(NPM_DIR) --no-audit --no-fund --no-save $(NPM_PACKAGES) \
	     > $(NPM_DIR)/install.log 2>&1; then echo "$(NPM_PACKAGES)" > $(NPM_DIR)/installed; \
	else echo "npm-deps: npm install failed ($(NPM_DIR)/install.log): the engine tests will skip"; fi

# make test builds and runs its binaries TEST_JOBS at a time (default: one a core; TEST_JOBS=1: one after
# the other). The binaries go longest first (TEST_LONGEST, as measured: `slowest binaries` at the end of
# its output), so that the last to finish is a short one (tests/run_tests.sh).
TEST_JOBS    ?= $(shell nproc 2>/dev/null || echo 1)
TEST_LONGEST := $(addprefix $(BUILD)/tests/,test_frame_check test_cli test_portals test_soak test_view \
                  test_hard_cases test_run test_photon_gather test_api test_motion_trail test_accuracy \
                  test_bake_after_edits)
TESTS_RUN    := $(foreach t,$(TEST_LONGEST),$(filter $(t),$(TESTS))) $(FUZZ_TESTS) \
                $(filter-out $(TEST_LONGEST),$(TESTS))

# npm-deps and the build are makes of their own, after deps (which may have just installed what they
# need: npm, mpicc for lmgi-mpi), whatever -j the caller gave; the build runs TEST_JOBS compilers at a time
test: deps
	@$(MAKE) --no-print-directory npm-deps
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) test-build
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) $(FUZZ_TESTS)
	@if command -v $(MPICC) > /dev/null 2>&1; then $(MAKE) --no-print-directory $(BUILD)/lmgi-mpi; \
	else echo "make test: no $(MPICC): the MPI test will skip"; fi
	@LMGI_BUILD=$(BUILD) LMGI_NPM=$(NPM_DIR) LMGI_TEST_JOBS=$(TEST_JOBS) sh tests/run_tests.sh $(TESTS_RUN)

# what make test runs, built (a target of its own: make says nothing of those already built)
.PHONY: test-build
test-build: all $(TESTS)
	@:

# make fuzz: FUZZ_INPUTS structured inputs through the whole pipeline under ASan + UBSan, split over
# FUZZ_JOBS processes with seeds 1..FUZZ_JOBS (each its own inputs), then FUZZ_API_SEQUENCES call
# sequences of 200 calls through the API the same way; logs in build/fuzz/.
FUZZ_INPUTS ?= 100000
FUZZ_API_SEQUENCES ?= 200
FUZZ_JOBS   ?= 2
fuzz: deps $(FUZZ_BUILD)/tests/fuzz_pipeline $(FUZZ_BUILD)/tests/fuzz_api
	@sh tests/run_fuzz.sh $(FUZZ_BUILD)/tests/fuzz_pipeline $(FUZZ_INPUTS) $(FUZZ_JOBS) build/fuzz
	@LMGI_FUZZ_API_STEPS=200 sh tests/run_fuzz.sh $(FUZZ_BUILD)/tests/fuzz_api $(FUZZ_API_SEQUENCES) $(FUZZ_JOBS) \
	  build/fuzz-api

test-asan: deps
	@$(MAKE) --no-print-directory BUILD=build/asan OPT="-O1 -g" \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" test

demo: deps all
	@sh tools/demo.sh $(BUILD)/lmgi

# The scaling rows use many-room scenes of 4, 16 and 64 rooms (about 89k, 354k and 1.4M triangles); the
# levels' gather table and the level bake 12 and 45 rooms (265k and 994k triangles).
BENCH_ROOMS := 4 16 64
bench: deps all $(BUILD)/gen_scenes
	@mkdir -p $(BUILD)/bench
	@for n in $(BENCH_ROOMS); do [ -f $(BUILD)/bench/rooms_$$n.glb ] || $(BUILD)/gen_scenes --rooms $$n $(BUILD)/bench/rooms_$$n.glb >/dev/null; done
	@[ -f $(BUILD)/bench/cornell_255.glb ] || $(BUILD)/gen_scenes --cornell-cells 255 $(BUILD)/bench/cornell_255.glb >/dev/null
	@for n in 12 45; do [ -f $(BUILD)/bench/rooms_$$n.glb ] || $(BUILD)/gen_scenes --rooms $$n $(BUILD)/bench/rooms_$$n.glb >/dev/null; done
	$(BUILD)/lmgi-dev bench --gather-scene $(BUILD)/bench/cornell_255.glb
	$(BUILD)/lmgi-dev bench-levels scenes/cornell.glb $(wildcard ../shared/scenes/occlusion-room/room_lit.glb \
	  ../shared/scenes/truck-town/town_lit.gltf) $(BUILD)/bench/rooms_12.glb $(BUILD)/bench/rooms_45.glb
	@echo "a generated level of 265,072 triangles (gen_scenes --rooms 12), baked at the defaults:"
	$(BUILD)/lmgi bake $(BUILD)/bench/rooms_12.glb --out $(BUILD)/bench/bake_rooms_12 --force 2>/dev/null
	$(BUILD)/lmgi bench --json $(BUILD)/bench/bench.json $(foreach n,$(BENCH_ROOMS),--scaling $(BUILD)/bench/rooms_$(n).glb)
	$(BUILD)/lmgi bench --edits bench/two_rooms_edits.json scenes/two_rooms.glb --json $(BUILD)/bench/edits.json
	$(if $(wildcard ../shared/scenes/occlusion-room/room_lit.glb),$(BUILD)/lmgi bench --edits bench/room_lit_edits.json \
	  ../shared/scenes/occlusion-room/room_lit.glb --json $(BUILD)/bench/edits_room_lit.json)
	$(BUILD)/lmgi bench --soak 100000 scenes/cornell.glb --size 32x32

# The full sweep of docs/tradeoff.md: make tradeoff TRADEOFF_SCENES="scenes/cornell.glb
# ../shared/scenes/cornell-box/CornellBox.glb scenes/two_rooms.glb"
# TRADEOFF_FLAGS="--edits bench/cornell_edits.json,bench/two_rooms_lag.json"; the shared level's lag:
# make tradeoff TRADEOFF_SCENES=../shared/scenes/occlusion-room/room_lit.glb
# TRADEOFF_FLAGS="--knobs hemicube_samples --quick --edits bench/room_lit_edits.json --frame-lag"
TRADEOFF_SCENES ?= scenes/cornell.glb
TRADEOFF_FLAGS  ?= --quick --edits bench/cornell_edits.json
tradeoff: deps all
	$(BUILD)/lmgi tradeoff $(TRADEOFF_SCENES) $(TRADEOFF_FLAGS) --out $(BUILD)/tradeoff

scenes: $(BUILD)/gen_scenes
	$(BUILD)/gen_scenes scenes

clean:
	rm -rf build demo

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
