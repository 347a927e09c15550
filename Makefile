# plume — top-level build. `make` builds libplume.{a,so} and the apps; `make test` runs the suite;
# `make asan` runs it under AddressSanitizer + UBSan; `make bench`, `make demo`, `make install`.
SHELL := /bin/bash
PREFIX ?= /usr/local
CC ?= cc
CXX ?= c++
OPT ?= -O2 -g
BUILD ?= build
DEPS_PKGS := ipopt nlopt hdf5 gsl jansson zlib
# the version (include/plume/base.h says the same; a test checks they agree): the shared library is
# libplume.so.MAJOR.MINOR with the soname libplume.so.MAJOR
VERSION_MAJOR := 3
VERSION_MINOR := 5
VERSION_PATCH := 0
SONAME := libplume.so.$(VERSION_MAJOR)
SOFILE := libplume.so.$(VERSION_MAJOR).$(VERSION_MINOR)

PKG_CFLAGS := $(shell pkg-config --cflags $(DEPS_PKGS) 2>/dev/null)
PKG_LIBS := $(shell pkg-config --libs $(DEPS_PKGS) 2>/dev/null)
CPPFLAGS += -I/usr/include/suitesparse $(PKG_CFLAGS)
# -fvisibility=hidden: libplume.so exports only what an installed header marks PLUME_API
# (lib/core/export.h); the internal functions the apps and tests call come from libplume.a
CFLAGS += -std=c11 -Wall -Wextra -Wpedantic -fPIC -fvisibility=hidden $(OPT) -D_POSIX_C_SOURCE=200809L
CXXFLAGS += -std=c++17 -Wall -Wextra -fPIC -fvisibility=hidden -fvisibility-inlines-hidden $(OPT)
LDLIBS += -lcholmod -lsuitesparseconfig $(PKG_LIBS) -lgmp -lmpfr -lgomp -lstdc++ -lm

# lib/ in rooms (docs/design.md): core, then io, solve, contact, and the steppers in sim; macro/ (its
# rooms: shell, the shell's physics; feather, the feather mesher; scene, scenes and their runner) and
# micro/ above, the experiment drivers (study, sweep, stability, the flat interface) in drivers/
# above those. The public face is include/plume/ (docs/library.md): one header a job, the umbrella
# include/plume/plume.h over them; it is all that make install puts on a user's include path
LIB_ROOMS := core io solve contact sim
LIB_C := $(foreach r,$(LIB_ROOMS),$(wildcard lib/$(r)/*.c)) $(wildcard micro/*.c) $(wildcard macro/*/*.c) $(wildcard drivers/*.c)
LIB_CXX := $(foreach r,$(LIB_ROOMS),$(wildcard lib/$(r)/*.cpp))
LIB_OBJ := $(patsubst %.c,$(BUILD)/%.o,$(LIB_C)) $(patsubst %.cpp,$(BUILD)/%.o,$(LIB_CXX))
APP_SRC := $(wildcard apps/*.c)
APPS := $(patsubst %.c,%,$(APP_SRC))
TEST_SRC := $(wildcard tests/*.c)
TEST_OBJ := $(patsubst %.c,$(BUILD)/%.o,$(TEST_SRC))
PUBLIC_HEADERS := $(wildcard include/plume/*.h)
HEADERS := $(PUBLIC_HEADERS) $(foreach r,$(LIB_ROOMS),$(wildcard lib/$(r)/*.h)) $(wildcard micro/*.h) $(wildcard macro/*/*.h) \
    $(wildcard drivers/*.h) tests/plume_tree.h
# the benchmarks (bench/bench_NAME.c), in the order make bench runs them; each has its block in
# docs/benchmarks.md, which scripts/bench-tables.py rewrites from the run's output (captured in
# $(BUILD)/bench/NAME.txt) and which make test checks against what `bench_NAME --header` prints.
# `make bench BENCHES=statics` runs one; `make bench-docs` rewrites the blocks from the captures.
BENCHES ?= traction micro plate feather bending statics wing bird unzip
BENCH_BINS := $(patsubst bench/%.c,$(BUILD)/%,$(wildcard bench/bench_*.c))
PRIVATE_HEADERS := $(foreach r,$(LIB_ROOMS),$(wildcard lib/$(r)/internal/*.h)) $(wildcard macro/*/internal/*.h) $(wildcard drivers/internal/*.h)

.PHONY: all deps deps-check test asan bench bench-docs demo docs install uninstall clean fuzz fuzz-build abi-check abi-update
all: $(BUILD)/libplume.a $(BUILD)/libplume.so $(APPS)

deps:
	@bash scripts/install-deps.sh

# before any compilation: one clear line naming the missing packages (and how to install them)
# instead of the first compiler error
deps-check:
	@bash scripts/install-deps.sh --check

$(BUILD)/%.o: %.c $(HEADERS) $(PRIVATE_HEADERS) | deps-check
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

$(BUILD)/%.o: %.cpp $(HEADERS) $(PRIVATE_HEADERS) | deps-check
	@mkdir -p $(dir $@)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -c $< -o $@

$(BUILD)/libplume.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/$(SOFILE): $(LIB_OBJ) lib/libplume.map
	$(CXX) -shared -Wl,-soname,$(SONAME) -Wl,--version-script,lib/libplume.map -o $@ $(LIB_OBJ) $(LDFLAGS) $(LDLIBS)

$(BUILD)/libplume.so: $(BUILD)/$(SOFILE)
	ln -sf $(SOFILE) $(BUILD)/$(SONAME)
	ln -sf $(SOFILE) $@

APP_HEADERS := $(wildcard apps/*.h)
apps/%: apps/%.c $(BUILD)/libplume.a $(HEADERS) $(APP_HEADERS)
	$(CC) $(CPPFLAGS) $(CFLAGS) $< -o $@ $(BUILD)/libplume.a $(LDFLAGS) $(LDLIBS)

# the sweep, the fit and the study are built with MPI when OpenMPI's compiler wrapper is there (scripts/install-deps.sh
# --mpi installs it), serial otherwise; the library never needs MPI. -lmpi comes first: Ipopt's
# sequential MUMPS (libdmumps_seq) exports a stub MPI_Init that would otherwise be the one called
MPICC := $(shell command -v mpicc 2>/dev/null)
apps/sweep apps/fit apps/study: apps/%: apps/%.c $(BUILD)/libplume.a $(HEADERS) $(APP_HEADERS)
	$(if $(MPICC),$(MPICC) -DPLUME_MPI,$(CC)) $(CPPFLAGS) $(CFLAGS) $< -o $@ $(if $(MPICC),-lmpi) $(BUILD)/libplume.a \
	    $(LDFLAGS) $(LDLIBS)

$(BUILD)/run_tests: $(TEST_OBJ) $(BUILD)/libplume.a
	$(CC) $(CFLAGS) $(TEST_OBJ) -o $@ $(BUILD)/libplume.a $(LDFLAGS) $(LDLIBS)

$(TEST_OBJ): $(wildcard tests/*.h)

# The README's test command. TESTS=substring runs a subset.
# OpenBLAS's OpenMP threads spin while they wait; on a 2-core machine that steals the main
# thread's core (measured: tilted traction at 4e4 elements 2.19 -> 1.99 s, feather 0.119 ->
# 0.093 s a frame with passive waiting). The tests, benchmarks and demo run with it; see README.
OMP_ENV := OMP_WAIT_POLICY=$${OMP_WAIT_POLICY:-passive}

test: deps
	@$(MAKE) --no-print-directory all $(BUILD)/run_tests $(BENCH_BINS)
	$(OMP_ENV) TESTS="$(TESTS)" bash scripts/run-tests.sh $(BUILD)

# the app tests run the regular apps/ binaries, not the sanitised build: make test has run them, so
# the sanitised suite leaves them out (the names with these substrings), and the micro-against-macro
# check at the finest barb spacing (a minute here, whose code the sanitised suite runs in smaller
# tests); PLUME_TEST_SMALL makes the largest tests run smaller instances of the same code
ASAN_SKIP ?= test_app_,_app_,_hooked_cohesive
asan: deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory BUILD=build-asan OPT="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer" \
	    LDFLAGS="-fsanitize=address,undefined" build-asan/run_tests
	cd tests && $(OMP_ENV) PLUME_TEST_SMALL=1 PLUME_TEST_SKIP=$(ASAN_SKIP) ASAN_OPTIONS=detect_leaks=1 \
	    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ../build-asan/run_tests $(TESTS)

# libFuzzer harnesses (tests/fuzz/README.md): the library built by clang with ASan + UBSan and
# fuzzer coverage in build-fuzz/, each harness run on a scratch copy of its committed corpus for
# FUZZ_SECONDS seconds; a crash fails the target and leaves its reproducer in build-fuzz/
FUZZ_SECONDS ?= 10
# a fixed seed: the same mutations on every CI run (0: libFuzzer picks one)
FUZZ_SEED ?= 1
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_HARNESSES := $(patsubst tests/fuzz/fuzz_%.c,%,$(wildcard tests/fuzz/fuzz_*.c))
FUZZ_BINS := $(addprefix build-fuzz/fuzz_,$(FUZZ_HARNESSES))
build-fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/*.h build-fuzz/libplume.a
	clang $(CPPFLAGS) -std=c11 -D_POSIX_C_SOURCE=200809L -O1 -g $(FUZZ_SAN) -fsanitize=fuzzer -c $< -o $@.o
	clang++ $(FUZZ_SAN) -fsanitize=fuzzer $@.o -o $@ build-fuzz/libplume.a $(LDFLAGS) $(LDLIBS)
fuzz-build: deps
	@command -v clang >/dev/null || { echo "make fuzz needs clang with libFuzzer: apt-get install clang libclang-rt-14-dev" >&2; exit 1; }
	@$(MAKE) --no-print-directory BUILD=build-fuzz CC=clang CXX=clang++ OPT="-O1 -g $(FUZZ_SAN) -fsanitize=fuzzer-no-link" \
	    LDFLAGS="$(FUZZ_SAN)" build-fuzz/libplume.a
	@$(MAKE) --no-print-directory $(FUZZ_BINS)
fuzz: fuzz-build
	@cd tests && for h in $(FUZZ_HARNESSES); do \
	    rm -rf ../build-fuzz/corpus/$$h && mkdir -p ../build-fuzz/corpus/$$h && \
	    echo "fuzz_$$h: $(FUZZ_SECONDS) s" && \
	    PLUME_SRC=.. ../build-fuzz/fuzz_$$h -max_total_time=$(FUZZ_SECONDS) -seed=$(FUZZ_SEED) -timeout=20 -rss_limit_mb=2560 \
	        -print_final_stats=1 -artifact_prefix=../build-fuzz/crash-$$h- \
	        ../build-fuzz/corpus/$$h fuzz/corpus/$$h 2>&1 | grep -E "stat::number_of_executed_units|stat::average_exec_per_sec|ERROR|SUMMARY|crash-" ; \
	    test $${PIPESTATUS[0]} -eq 0 || exit 1; \
	done; echo "fuzz: every harness ran $(FUZZ_SECONDS) s without a crash"

# deps first, then a sub-make: pkg-config flags are read when make starts, so they must be read
# again once missing packages are installed
bench: deps
	@$(MAKE) --no-print-directory all $(BENCH_BINS)
	$(OMP_ENV) python3 scripts/bench-tables.py run $(BUILD) $(BENCHES)

bench-docs:
	python3 scripts/bench-tables.py write $(BUILD) $(BENCHES)

$(BUILD)/bench_%: bench/bench_%.c $(BUILD)/libplume.a
	$(CC) $(CPPFLAGS) $(CFLAGS) $< -o $@ $(BUILD)/libplume.a $(LDFLAGS) $(LDLIBS)

# bench_feather's bending-model part (--models) lives in its own file
$(BUILD)/bench_feather: bench/bench_feather.c bench/feather_models.c bench/feather_models.h $(BUILD)/libplume.a
	$(CC) $(CPPFLAGS) $(CFLAGS) bench/bench_feather.c bench/feather_models.c -o $@ $(BUILD)/libplume.a $(LDFLAGS) $(LDLIBS)

# The README's main command: the tilted traction test on the shipped parameters, both solvers.
demo: deps
	@$(MAKE) --no-print-directory all data/feather/moduli_table3a.h5
	$(OMP_ENV) bash scripts/demo.sh

# the bending moduli of data/feather/scene_anisotropic_homogenised.json: homogenised from the
# explicit-barbule layout (about 10 s), not kept in git
data/feather/moduli_table3a.h5: data/layout_barbules_table3a.json apps/homogenize
	$(OMP_ENV) ./apps/homogenize --config $< -o $@

# the membrane and bending moduli of data/feather/scene_from_cell.json: homogenised from the
# real-scale layout (under a second), not kept in git
data/feather/moduli_feather_si.h5: data/layout_feather_si.json apps/homogenize
	$(OMP_ENV) ./apps/homogenize --config $< -o $@

# the vane's moduli and the barb lines' separation law of data/feather/scene_unzip.json: homogenised
# from the layout with hooks (about 10 s), not kept in git
data/feather/moduli_hooks.h5: data/layout_hooks.json apps/homogenize
	$(OMP_ENV) ./apps/homogenize --config $< -o $@

# The API reference: Doxygen over the public headers (include/plume/) (docs/Doxyfile; the main page is
# docs/api.md), HTML in $(BUILD)/docs/html. Any warning fails it and is printed: an undocumented
# public function, struct, field, enum value, typedef or macro, or a doc comment Doxygen cannot read.
# doxygen is not a build dependency (plain make does not ask for it); make deps installs it.
docs:
	@command -v doxygen >/dev/null || { echo "make docs: doxygen not found; install it with make deps (apt-get install doxygen)" >&2; exit 1; }
	@rm -rf $(BUILD)/docs && mkdir -p $(BUILD)/docs
	@PLUME_DOCS_OUT=$(BUILD)/docs PLUME_VERSION=$(VERSION_MAJOR).$(VERSION_MINOR).$(VERSION_PATCH) \
	    doxygen docs/Doxyfile >$(BUILD)/docs/doxygen.log 2>&1; rc=$$?; \
	    n=$$(grep -c . $(BUILD)/docs/warnings.log 2>/dev/null || true); \
	    if [ $$rc -ne 0 ] || [ "$${n:-0}" -gt 0 ]; then \
	        if [ "$${n:-0}" -gt 0 ]; then sed "s|$$PWD/||" $(BUILD)/docs/warnings.log >&2; else cat $(BUILD)/docs/doxygen.log >&2; fi; \
	        echo "make docs: failed, $${n:-0} doxygen warnings (docs/Doxyfile treats every warning as an error)" >&2; exit 1; \
	    fi
	@echo "API reference: $(BUILD)/docs/html/index.html"

# the ABI of the public face against the committed baseline abi/libplume.abi (libabigail's abidw
# and abidiff, Debian's abigail-tools; docs/development.md, "The public face and the ABI")
abi-check: $(BUILD)/libplume.so
	bash scripts/abi-check.sh $(BUILD)
abi-update: $(BUILD)/libplume.so
	bash scripts/abi-check.sh $(BUILD) --update

# the public headers (include/plume/*.h) in PREFIX/include/plume/; pkg-config's Cflags point at
# PREFIX/include, so other C code writes #include <plume/plume.h> (or <plume/scene.h>, ...)
install: all
	install -d $(DESTDIR)$(PREFIX)/lib $(DESTDIR)$(PREFIX)/include/plume $(DESTDIR)$(PREFIX)/lib/pkgconfig $(DESTDIR)$(PREFIX)/bin
	install -m 644 $(BUILD)/libplume.a $(BUILD)/$(SOFILE) $(DESTDIR)$(PREFIX)/lib/
	ln -sf $(SOFILE) $(DESTDIR)$(PREFIX)/lib/$(SONAME)
	ln -sf $(SOFILE) $(DESTDIR)$(PREFIX)/lib/libplume.so
	install -m 644 $(PUBLIC_HEADERS) $(DESTDIR)$(PREFIX)/include/plume/
	install -m 755 $(APPS) $(DESTDIR)$(PREFIX)/bin/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBS@|$(LDLIBS)|' -e 's|@VERSION@|$(VERSION_MAJOR).$(VERSION_MINOR).$(VERSION_PATCH)|' \
	    plume.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/plume.pc

# everything install put there, and nothing else
uninstall:
	rm -f $(DESTDIR)$(PREFIX)/lib/libplume.a $(DESTDIR)$(PREFIX)/lib/$(SOFILE) $(DESTDIR)$(PREFIX)/lib/$(SONAME) \
	    $(DESTDIR)$(PREFIX)/lib/libplume.so $(DESTDIR)$(PREFIX)/lib/pkgconfig/plume.pc
	rm -f $(addprefix $(DESTDIR)$(PREFIX)/bin/,$(notdir $(APPS)))
	rm -rf $(DESTDIR)$(PREFIX)/include/plume

clean:
	rm -rf build build-asan build-fuzz $(APPS)
