# Thin wrapper over CMake. Every target installs missing Debian packages first, so on a fresh
# Debian 12 machine `make demo` and `make test` are all it takes.
BUILD      ?= build
ASAN_BUILD ?= build-asan
FUZZ_BUILD ?= build-fuzz
JOBS       ?= $(shell nproc)
# Tests side by side: each test that opens DDS holds a domain of its own (tests/support/test_domain.py),
# and those that must run alone are RUN_SERIAL (CONTRIBUTING.md, Tests). One more than the cores:
# the tests mostly wait (about 95 CPU-s in a run of 150 s on 2 cores; docs/development.md).
CTEST_JOBS ?= $(shell echo $$(( $$(nproc) + 1 )))
# The test suites that run Fast DDS on the host get a /dev/shm of their own, so that a file another
# run or build left there cannot abort them (tests/support/private_shm.sh says why).
PRIVATE_SHM = $(CURDIR)/tests/support/private_shm.sh
FUZZ_SECONDS ?= 30
# make test's fuzzing: each fuzzer this long, from its seed corpus (a smoke run that keeps the loop
# short); .ci/run gives it 20 s and `make fuzz FUZZ_SECONDS=600` is the long run.
TEST_FUZZ_SECONDS ?= 10
# Fast DDS 2.9.1 deletes an RTPSReader through the wrong type in its own destructor
# (~RTPSReader, 64 vs 56 bytes); that report is about the library, not about rsg.
ASAN_OPTIONS ?= new_delete_type_mismatch=0
# Debian packages by need: build, run (make demo installs these two), test (make deps adds it).
packages    = $(shell grep -hv '^\s*\#' $(addprefix docker/packages/,$(addsuffix .txt,$(1))))
# Project-local tools from PyPI and the Go module proxy, pinned with hashes (git-ignored).
DEPS_DIR   ?= $(CURDIR)/.deps
# Where Go's module and build caches are kept for every checkout on this machine (content-addressed,
# like ccache's ~/.cache/ccache): a fresh clone's make deps builds rsg-mcap-check in 0.4 s, not 20 s.
export RSG_CACHE_DIR ?= $(HOME)/.cache/rsg
# Every CMake configure gets these: ccache (docker/packages/build.txt) makes the three builds of
# `make test` and a rebuild after a branch switch cheap (paths relative to the checkout, so clones
# share the cache); RSG_DEPS_DIR is where make deps put the project-local tools.
CMAKE_COMMON := -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache \
                -DRSG_DEPS_DIR=$(DEPS_DIR)
# Ninja for a new tree: it schedules the whole graph, so both cores stay busy across targets where
# CMake's Makefiles leave one idle at each target's end (make demo's four tools: 133 s against 168 s,
# the same CPU time; docs/development.md). A tree configured before keeps its generator.
generator = $(if $(wildcard $(1)/CMakeCache.txt),,-G Ninja)
export CCACHE_BASEDIR := $(CURDIR)
export CCACHE_NOHASHDIR := true
SUDO       := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# pipefail: a test run piped through tee must still fail the target.
SHELL      := /bin/bash
.SHELLFLAGS := -o pipefail -c


.PHONY: all deps deps-test deps-run build build-tests build-demo install test test-long unit-asan fuzz fuzz-build demo bench format clean wireshark-plugin

all: build

# Installs what is missing of the Debian packages of the needs named in $(1).
define apt_install
	@missing=$$(for p in $(call packages,$(1)); do \
	  dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "make deps: installing" $$missing; \
	  echo 'wireshark-common wireshark-common/install-setuid boolean false' | $(SUDO) debconf-set-selections; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi
endef

# What building and running needs: enough for make demo.
deps-run:
	$(call apt_install,build run)

# Everything make test needs: Debian packages, npm packages, the Python environments (ROS 2 Jazzy's
# among them: its rclpy nodes and rosidl) and Go tools.
deps-test: deps-run
	$(call apt_install,test package)
	@# Node and npm for the tests that read MCAP files with @mcap/core (Debian's, unless a node is there).
	@command -v npm >/dev/null || { $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends nodejs npm; }
	@[ tests/tools/record/package-lock.json -ot tests/tools/record/node_modules/.package-lock.json ] || \
	  npm ci --prefix tests/tools/record --no-audit --no-fund
	@[ tests/tools/view/package-lock.json -ot tests/tools/view/node_modules/.package-lock.json ] || \
	  npm ci --prefix tests/tools/view --no-audit --no-fund
	@for script in tools/deps/*.sh; do DEPS_DIR=$(DEPS_DIR) $$script || exit 1; done

# Everything every suite needs: since ROS 2 Jazzy is make test's ROS 2 too, what deps-test installs.
deps: deps-test

# The tests' build and the demo's are one tree with one set of flags: -O2 with line tables only
# (-g1: file:line in every stack and sanitizer report, at about a third less compiling than full
# debug information), so that `make test` after `make demo` compiles only what the demo did not.
OPT_FLAGS := -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG" \
             "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -g1 -DNDEBUG"
# That tree and the sanitizer tree are unity builds (CMake's CMAKE_UNITY_BUILD: each target's sources
# compiled eight to a translation unit), which the two commands meet cold: a tenth to a third less
# compiling, as measured (docs/development.md). The fuzz, package and Fast DDS 2.14 / 3 trees compile each file
# alone, so a file that leans on its neighbour's includes still fails in CI (CONTRIBUTING.md).
UNITY_FLAGS := -DCMAKE_UNITY_BUILD=ON

# The product, what make install installs, with only the build and run packages (no npm, Python
# environments or Go: those are the tests'): the tests left unconfigured on a fresh tree, as for the
# demo, and kept on a tree that has them (make build-tests).
build: deps-run
	cmake -S . -B $(BUILD) $(call generator,$(BUILD)) $(OPT_FLAGS) $(UNITY_FLAGS) $(if $(wildcard $(BUILD)/CMakeCache.txt),,-DRSG_BUILD_TESTS=OFF) $(CMAKE_COMMON)
	cmake --build $(BUILD) -j $(JOBS)

# The product and every test and benchmark, with everything the tests need (make deps).
build-tests: deps-test
	cmake -S . -B $(BUILD) $(call generator,$(BUILD)) $(OPT_FLAGS) $(UNITY_FLAGS) -DRSG_BUILD_TESTS=ON $(CMAKE_COMMON)
	cmake --build $(BUILD) -j $(JOBS) && echo "build-tests: $(BUILD) built in $$SECONDS s"

# Tools, profiles, IDL, client libraries and headers, and the CMake package (find_package(rsg)).
# PREFIX defaults to CMake's (/usr/local): make install PREFIX=/opt/rsg
install: build
	cmake --install $(BUILD) $(if $(PREFIX),--prefix $(PREFIX))

# Unit tests again under AddressSanitizer + UndefinedBehaviorSanitizer.
unit-asan: deps-test
	cmake -S . -B $(ASAN_BUILD) $(call generator,$(ASAN_BUILD)) -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG=-g1 -DCMAKE_C_FLAGS_DEBUG=-g1 \
	      -DRSG_SANITIZE=ON $(UNITY_FLAGS) $(CMAKE_COMMON)
	cmake --build $(ASAN_BUILD) -j $(JOBS) --target unit_tests && echo "unit-asan: $(ASAN_BUILD) built in $$SECONDS s"
	cd $(ASAN_BUILD) && ASAN_OPTIONS=$(ASAN_OPTIONS) $(PRIVATE_SHM) ctest --output-on-failure -j $(CTEST_JOBS) -L unit 2>&1 | tee ctest.log && \
	  echo "unit-asan: ctest took $$SECONDS s"

fuzz-build: deps-test
	CC=clang-14 CXX=clang++-14 cmake -S . -B $(FUZZ_BUILD) $(call generator,$(FUZZ_BUILD)) -DRSG_FUZZ=ON $(OPT_FLAGS) $(CMAKE_COMMON)
	cmake --build $(FUZZ_BUILD) -j $(JOBS) && echo "fuzz-build: $(FUZZ_BUILD) built in $$SECONDS s"

# Each fuzzer for FUZZ_SECONDS, JOBS at a time (make fuzz FUZZ_SECONDS=600 for a long run).
fuzz: fuzz-build
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_JOBS=$(JOBS) tests/fuzz/run_fuzzers.sh $(FUZZ_BUILD) 2>&1 | tee $(FUZZ_BUILD)/fuzz.log

# What a contributor runs: every ctest test but those labelled long, side by side; the unit tests
# again under ASan+UBSan; every fuzzer for TEST_FUZZ_SECONDS (docs/development.md has the time each part takes).
test: build-tests
	cd $(BUILD) && $(PRIVATE_SHM) ctest --output-on-failure -j $(CTEST_JOBS) -LE long 2>&1 | tee ctest.log && \
	  echo "make test: ctest took $$SECONDS s"
	$(MAKE) unit-asan
	$(MAKE) fuzz FUZZ_SECONDS=$(TEST_FUZZ_SECONDS)
	@tests/summarize.sh $(BUILD)/ctest.log $(ASAN_BUILD)/ctest.log -- $(FUZZ_BUILD)/fuzz.log

# The long scenarios (ctest label long: network namespaces, reliability under load, churn and
# scale), most of them RUN_SERIAL; .ci/run runs it after make test.
test-long: build-tests
	cd $(BUILD) && $(PRIVATE_SHM) ctest --output-on-failure -j $(CTEST_JOBS) -L long 2>&1 | tee ctest-long.log
	@tests/summarize.sh $(BUILD)/ctest-long.log --

# Only what the demo runs, with only the build and run packages: in $(BUILD) with its flags, the
# tests left unconfigured on a fresh tree (no GTest or benchmark needed yet) and kept on a tree
# that has them, so that a later `make test` reuses every object the demo compiled.
DEMO_TARGETS := rsg_gateway rsg_sim rsg_echo rsg_view
# The other tools a user meets next in the guides (record and replay, rsg_frame): built by make demo
# after the demo has run, so that the first live sample comes no later (three more main.cpp, each
# about 20 s of compiling: docs/development.md).
USER_TARGETS := rsg_record rsg_replay rsg_frame
build-demo: deps-run
	cmake -S . -B $(BUILD) $(call generator,$(BUILD)) $(OPT_FLAGS) $(UNITY_FLAGS) $(if $(wildcard $(BUILD)/CMakeCache.txt),,-DRSG_BUILD_TESTS=OFF) $(CMAKE_COMMON)
	cmake --build $(BUILD) -j $(JOBS) --target $(DEMO_TARGETS)

demo: build-demo
	src/tools/demo.sh $(BUILD)/bin
	@echo "make demo: now building $(USER_TARGETS) into $(BUILD)/bin (record and replay: docs/record-replay.md)"
	cmake --build $(BUILD) -j $(JOBS) --target $(USER_TARGETS)

bench: deps build-tests
	tests/bench/run_bench.sh $(BUILD)

# The SEND_BUF dissector into Wireshark's personal Lua plugins folder (where `tshark -G folders` says).
wireshark-plugin:
	@dir=$$(tshark -G folders 2>/dev/null | sed -n 's/^Personal Lua Plugins:[[:space:]]*//p'); \
	dir=$${dir:-$$HOME/.local/lib/wireshark/plugins}; \
	mkdir -p "$$dir" && install -m 644 tools/wireshark/rsg_sendbuf.lua "$$dir/" && \
	echo "installed $$dir/rsg_sendbuf.lua: restart Wireshark, then filter on sendbuf"

# Where the time of a fresh build and of ctest goes (docs/development.md): its own tree, no ccache.
.PHONY: time-report
time-report: deps-test
	tools/time_report.py --build build-time

format:
	git ls-files '*.cpp' '*.hpp' '*.h' '*.c' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD) build-demo build-fdds3 build-fdds214 build-time $(PKG_BUILD)

# Fast DDS 3.6 (ROS 2 Lyrical's line: Debian experimental's 3.6.1 on Debian 13) in a cached chroot,
# and across versions with $(BUILD)'s 2.9.1 and make test-fastdds214's 2.14.5 on the host
# (tests/fastdds3/run.sh, docs/fastdds-versions.md). Its own tree, build-fdds3/; the 2.14 side is
# make test-fastdds214's build-fdds214 (run that first: without it the 2.14 <-> 3.6 tests fail).
.PHONY: test-fastdds3 bench-fastdds3
test-fastdds3: build-tests
	JOBS=$(JOBS) $(PRIVATE_SHM) tests/fastdds3/run.sh $(BUILD) 2>&1 | tee $(BUILD)/test-fastdds3.log

# Fast DDS 2.14.5 (ROS 2 Jazzy's LTS, its PyPI wheels in $(DEPS_DIR)/fastdds214) found on
# CMAKE_PREFIX_PATH, and across versions with $(BUILD)'s 2.9.1 (tests/fastdds214/run.sh,
# docs/fastdds-versions.md). Its own tree, build-fdds214/.
.PHONY: test-fastdds214
test-fastdds214: deps build-tests
	JOBS=$(JOBS) DEPS_DIR=$(DEPS_DIR) $(PRIVATE_SHM) tests/fastdds214/run.sh $(BUILD) 2>&1 | tee $(BUILD)/test-fastdds214.log

# make bench's e2e suite on 2.9 (host) and 3.x (chroot) back to back, side by side (docs/benchmarks/fastdds3/).
bench-fastdds3: build-tests
	JOBS=$(JOBS) tests/fastdds3/bench.sh $(BUILD)

# The container image (docs/container.md) with the engine that works here: Docker when `docker info`
# answers, else podman with docker/containers.conf (docker/engine.sh). IMAGE names it.
IMAGE ?= rsg
.PHONY: image test-image
image:
	docker/build-image.sh $(IMAGE)

# Builds the image from make package's Release tree (docker/build-image.sh --tools-from: the
# binaries the .deb holds, compiled once for both), then runs the pipeline, rsg_view and
# docker/compose.yaml in containers. make image compiles in the Dockerfile's build stage instead.
test-image: deps package
	RSG_IMAGE=$(IMAGE) RSG_IMAGE_TOOLS_FROM=$(PKG_BUILD) tests/image/run.sh

# The Debian package (cmake/rsg_package.cmake, docs/service.md): a Release build of its own without
# the tests, the man pages from help2man, CPack's DEB generator (version: project(), Depends:
# dpkg-shlibdeps), then lintian, which must report no error. The .deb is in $(PKG_BUILD)/packages/.
# Compiled with Debian's build flags with every hardening option (dpkg-buildflags: fortify, stack
# protector, relro, bindnow), as a package built by debhelper would be, less -g (CPack strips the
# binaries: debug info would only slow the build), -O2 (Release's -O3) and -ffile-prefix-map.
PKG_BUILD ?= build-pkg
PKG_FLAGS = $$(DEB_BUILD_MAINT_OPTIONS=hardening=+all dpkg-buildflags --get $(1) | tr ' ' '\n' | \
              grep -vE '^(-g|-O2|-ffile-prefix-map=.*)$$' | tr '\n' ' ')
.PHONY: package test-service
package: deps-run
	$(call apt_install,package)
	cmake -S . -B $(PKG_BUILD) $(call generator,$(PKG_BUILD)) -DCMAKE_BUILD_TYPE=Release -DRSG_BUILD_TESTS=OFF -DCMAKE_INSTALL_PREFIX=/usr $(CMAKE_COMMON) \
	  -DCMAKE_C_FLAGS="$(call PKG_FLAGS,CPPFLAGS) $(call PKG_FLAGS,CFLAGS)" \
	  -DCMAKE_CXX_FLAGS="$(call PKG_FLAGS,CPPFLAGS) $(call PKG_FLAGS,CXXFLAGS)" \
	  -DCMAKE_EXE_LINKER_FLAGS="$(call PKG_FLAGS,LDFLAGS)"
	cmake --build $(PKG_BUILD) -j $(JOBS) --target all rsg_man
	rm -rf $(PKG_BUILD)/packages
	cd $(PKG_BUILD) && cpack -G DEB
	lintian --fail-on error --info $(PKG_BUILD)/packages/rsg_*.deb

# The package under a real systemd as PID 1 (tests/service/run.sh): installed with apt-get into a
# clean Debian 12 container, the unit started, fed, killed, frozen, upgraded, read by a real rclpy
# node (make deps' ROS 2 environment: the type hashes), broken and purged.
test-service: package deps
	PKG_BUILD=$(PKG_BUILD) tests/service/run.sh
