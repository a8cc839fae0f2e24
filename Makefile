# linewise -- elastic Bezier curves annealed into line art.
# Targets: all (bin/linewise), deps, deps-mpi, mpi (bin/linewise-mpi), test, test-long, asan, fuzz, fuzz-build, run, bench, wire-figures,
# install, uninstall, clean.

CC      ?= cc
PREFIX  ?= /usr/local
# the library's folder under PREFIX (a multiarch one: lib/x86_64-linux-gnu)
LIBDIR  ?= lib
PKG_CONFIG ?= pkg-config
BUILD   ?= build
BIN     ?= bin
PKGS    := gsl cairo inih zlib libpng
OPT     ?= -O2
CFLAGS  ?= $(OPT) -g
# -ffp-contract=off: no fused multiply-add, which clang makes by default where the
# target has it, and which changes results (docs/NUMERICS.md, "Determinism and drift").
WARN    := -std=c11 -ffp-contract=off -Wall -Wextra -Wshadow -Wstrict-prototypes -Wno-unused-parameter
# What the build needs, apart from CPPFLAGS and LDLIBS, which a packager may set on the
# command line (make CPPFLAGS="$(dpkg-buildflags --get CPPFLAGS)") and so replace.
LW_CPPFLAGS := -Iinclude -D_POSIX_C_SOURCE=200809L $(shell $(PKG_CONFIG) --cflags $(PKGS) 2>/dev/null)
LW_LDLIBS := $(shell $(PKG_CONFIG) --libs $(PKGS) 2>/dev/null) -lm
OMP     := -fopenmp
# Each object lists the headers it includes in a .d file beside it, so a
# header's change rebuilds only what includes it.
DEPFLAGS := -MMD -MP

# locales: the locale test builds a decimal-comma locale with localedef;
# strace: the signal tests send a signal as a chosen file opens (inject=)
DEBS    := build-essential pkg-config libgsl-dev libcairo2-dev libpng-dev libinih-dev libstb-dev zlib1g-dev \
           libcriterion-dev gnuplot-nox clang libclang-rt-dev locales strace

LIB_SRC := $(filter-out src/main.c,$(wildcard src/*.c))
# The MPI build (make mpi): main.c with -DLW_MPI and src/mpi/, through
# mpicc; the plain build never needs MPI.  make, make test and make install
# build it too where mpicc is installed (make deps-mpi): a plain make left an
# older linewise-mpi beside a new linewise, resolving scenes another way.
MPICC   ?= mpicc
MPI_DEBS := libopenmpi-dev openmpi-bin
MPI_BIN := $(if $(shell command -v $(MPICC) 2>/dev/null),$(BIN)/linewise-mpi)
LIB_OBJ := $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o)
TEST_SRC := $(wildcard tests/test_*.c)
TEST_OBJ := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%.o) $(BUILD)/tests/stb_write.o
# The fuzz harnesses, compiled with cc into the suite, which replays the corpus.
FUZZ_NAMES := params state resume energy image points trace fieldfile
FUZZ_REPLAY_OBJ := $(FUZZ_NAMES:%=$(BUILD)/tests/fuzz_%.o)
TEST_JOBS ?= 2
# study tools (shell, gnuplot), installed as linewise-<name>
TOOLS   := seed-sweep param-sweep plot-run plot-sweep thread-scaling
# The example picture is generated (no third-party images in the repository).
PICTURE := params/picture.png

.PHONY: all deps deps-mpi mpi deps-animation test test-long asan fuzz fuzz-build run bench install uninstall clean docs \
        wire-figures
# The example picture too: params/example.ini, the scene a new user tries
# first, needs it.
all: $(BIN)/linewise $(PICTURE) $(MPI_BIN)

$(BUILD)/obj/%.o: src/%.c | $(BUILD)/obj
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(DEPFLAGS) $(LW_CPPFLAGS) $(CPPFLAGS) -c $< -o $@

# The commit a build is made from, "-dirty" where src/, include/ or this file
# differ from it (a source file not yet added too), or "unknown" outside
# linewise's own checkout (a copy inside another repository, a paper's,
# named that one's commit): `linewise --version`, summary.json and a run's
# scene.ini name it, as a release spans many changes of a run's files.
# version.o alone is compiled again when it changes ($(BUILD)/build-id is
# rewritten only then).
LW_GIT_TOP  := $(shell git rev-parse --show-toplevel 2>/dev/null)
LW_BUILD_ID := $(if $(filter $(realpath $(CURDIR)),$(realpath $(LW_GIT_TOP))),$(shell git rev-parse --short=12 \
               HEAD)$(if $(shell git status --porcelain -- src include Makefile 2>/dev/null | head -c1),-dirty),unknown)
$(BUILD)/build-id: FORCE | $(BUILD)/obj
	@echo '$(LW_BUILD_ID)' > $@.tmp && if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi
$(BUILD)/obj/version.o build-fuzz/obj/version.o: LW_CPPFLAGS += -DLW_BUILD_ID='"$(LW_BUILD_ID)"'
$(BUILD)/obj/version.o build-fuzz/obj/version.o: $(BUILD)/build-id
FORCE:

$(BUILD)/liblinewise.a: $(LIB_OBJ)
	rm -f $@ && $(AR) rcs $@ $^

# (main.c alone, so any header's change compiles it again)
$(BIN)/linewise: src/main.c $(wildcard include/linewise/*.h) $(BUILD)/liblinewise.a | $(BIN)
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(LW_CPPFLAGS) $(CPPFLAGS) $< -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) $(LW_LDLIBS)

mpi: $(BIN)/linewise-mpi

$(BIN)/linewise-mpi: src/main.c $(wildcard src/mpi/*.c) $(wildcard include/linewise/*.h) $(BUILD)/liblinewise.a | $(BIN)
	$(MPICC) $(WARN) $(CFLAGS) $(OMP) $(LW_CPPFLAGS) $(CPPFLAGS) -DLW_MPI src/main.c $(wildcard src/mpi/*.c) -o $@ \
	  $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) $(LW_LDLIBS)

$(BUILD)/tests/%.o: tests/%.c | $(BUILD)/tests
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(DEPFLAGS) $(LW_CPPFLAGS) $(CPPFLAGS) -Itests -c $< -o $@

# stb_image_write (the image tests' JPEG writer) shifts signed ints out of
# range: built without UBSan, so that `make asan` reports only our code
$(BUILD)/tests/stb_write.o: tests/stb_write.c | $(BUILD)/tests
	$(CC) $(WARN) $(CFLAGS) -fno-sanitize=undefined $(LW_CPPFLAGS) $(CPPFLAGS) -c $< -o $@

$(BUILD)/tests/fuzz_%.o: tests/fuzz/fuzz_%.c | $(BUILD)/tests
	$(CC) $(WARN) $(CFLAGS) $(DEPFLAGS) $(LW_CPPFLAGS) $(CPPFLAGS) -DLLVMFuzzerTestOneInput=lw_fuzz_$*_one -c $< -o $@

$(BUILD)/tests/run: $(TEST_OBJ) $(FUZZ_REPLAY_OBJ) $(BUILD)/liblinewise.a
	$(CC) $(CFLAGS) $(OMP) $(TEST_OBJ) $(FUZZ_REPLAY_OBJ) -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) $(LW_LDLIBS) -lcriterion

$(BUILD)/obj $(BUILD)/tests $(BIN):
	mkdir -p $@

# The suite runs the binary too (CLI tests), so both are built first, and
# it checks that every bundled scene builds, the image scene included.
# (the MPI tests skip where mpirun cannot start a process, as a build
# chroot without a network interface: they failed there, a minute each)
test: $(BIN)/linewise $(MPI_BIN) $(BUILD)/tests/run $(PICTURE)
	@mpi=$(if $(MPI_BIN),$(CURDIR)/$(MPI_BIN)); \
	if [ -n "$$mpi" ] && ! command -v mpirun >/dev/null; then \
	  echo "make test: mpirun is not installed (make deps-mpi): the MPI tests skip" >&2; mpi=; \
	elif [ -n "$$mpi" ] && ! OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
	  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan-mpi.supp:print_suppressions=0 \
	  ASAN_OPTIONS=$${ASAN_OPTIONS:+$$ASAN_OPTIONS:}fast_unwind_on_malloc=0 timeout 60 \
	  mpirun --oversubscribe -n 1 "$$mpi" --version >/dev/null 2>&1; then \
	  echo "make test: mpirun cannot start $$mpi here (no network interface?): the MPI tests skip" >&2; mpi=; fi; \
	echo "LW_BIN=$(CURDIR)/$(BIN)/linewise LW_MPI_BIN=$$mpi LW_ROOT=$(CURDIR) $(BUILD)/tests/run --jobs $(TEST_JOBS)"; \
	LW_BIN=$(CURDIR)/$(BIN)/linewise LW_MPI_BIN=$$mpi LW_ROOT=$(CURDIR) $(BUILD)/tests/run --jobs $(TEST_JOBS)

# The long statistical and stress tests (LW_LONG=1 scales them up; minutes).
test-long: $(BIN)/linewise $(BUILD)/tests/run $(PICTURE)
	LW_LONG=1 LW_BIN=$(CURDIR)/$(BIN)/linewise LW_ROOT=$(CURDIR) $(BUILD)/tests/run --jobs $(TEST_JOBS) \
	  --filter '@(stats|hard|crash|transdim)/*'

asan:
	LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan-criterion.supp:print_suppressions=0 \
	$(MAKE) BUILD=build-asan BIN=build-asan/bin OPT=-O1 \
	  CFLAGS="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer" \
	  LDFLAGS="-fsanitize=address,undefined" test

# Fuzzing (libFuzzer, needs clang): each harness runs FUZZ_TIME seconds on
# its seed corpus; new inputs go to build-fuzz/corpus, crashes to
# build-fuzz/crashes.  The whole library is built (the resume harness
# reaches most of it), so no module list can go stale; `fuzz-build` only
# links the harnesses (CI runs it).  FUZZ_FLAGS adds libFuzzer options,
# e.g. FUZZ_FLAGS=-runs=1000000.  The harnesses write their inputs to files
# (the readers take paths) in FUZZ_TMP, a RAM disk where there is one: the
# writers fsync, which on a real disk costs 20 times the throughput.
FUZZ_TMP  ?= $(if $(wildcard /dev/shm),/dev/shm,/tmp)
FUZZ_CC   ?= clang
FUZZ_TIME ?= 60
FUZZ_FLAGS ?=
FUZZ_OBJ  := $(LIB_SRC:src/%.c=build-fuzz/obj/%.o)
FUZZ_SAN  := -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined \
             -DLW_IMAGE_MAX_PIXELS=4194304 -DFUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
FUZZ_WARN := $(WARN) -Wno-unknown-pragmas

build-fuzz/obj/%.o: src/%.c | build-fuzz/obj
	$(FUZZ_CC) $(FUZZ_WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link $(DEPFLAGS) $(LW_CPPFLAGS) $(CPPFLAGS) -c $< -o $@

build-fuzz/fuzz_%: tests/fuzz/fuzz_%.c $(wildcard tests/fuzz/*.h) $(FUZZ_OBJ)
	$(FUZZ_CC) $(FUZZ_WARN) $(FUZZ_SAN) -fsanitize=fuzzer $(LW_CPPFLAGS) $(CPPFLAGS) $< $(FUZZ_OBJ) -o $@ $(LDLIBS) $(LW_LDLIBS)

# kept between runs (make would delete them as intermediates)
.SECONDARY: $(FUZZ_OBJ)

build-fuzz/obj:
	mkdir -p $@

fuzz-build: $(FUZZ_NAMES:%=build-fuzz/fuzz_%)

fuzz: fuzz-build
	for t in $(FUZZ_NAMES); do \
	  mkdir -p build-fuzz/corpus/$$t build-fuzz/crashes && \
	  TMPDIR=$(FUZZ_TMP) build-fuzz/fuzz_$$t -max_total_time=$(FUZZ_TIME) -timeout=10 $(FUZZ_FLAGS) -artifact_prefix=build-fuzz/crashes/$$t- \
	    build-fuzz/corpus/$$t tests/fuzz/corpus/$$t || exit 1; \
	done

# apt-get installs as root only: said, with the way, before it fails on its
# lock file
AS_ROOT = { [ "$$(id -u)" = 0 ] || { echo "the packages install with apt-get, as root: sudo make $@" >&2; exit 1; }; } &&

deps:
	@command -v dpkg >/dev/null || { echo "make deps installs Debian packages with apt-get, and this system has no dpkg: install GSL, cairo, libpng, inih, stb, Criterion and gnuplot by its own means (README)"; exit 1; }; \
	missing=""; for p in $(DEBS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  $(AS_ROOT) echo "installing:$$missing" && apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; \
	else echo "all build dependencies present"; fi

# Open MPI for the MPI build (make mpi) only.
deps-mpi:
	@missing=""; for p in $(MPI_DEBS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  $(AS_ROOT) echo "installing:$$missing" && apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; \
	else echo "all MPI dependencies present"; fi

# ffmpeg for tools/animate.sh only: not needed to build or test.
deps-animation:
	@dpkg -s ffmpeg >/dev/null 2>&1 || { $(AS_ROOT) apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ffmpeg; }

run: bin/linewise $(PICTURE)
	bin/linewise run params/example.ini --out out/example

# (run on the machine that builds: its compiler, flags and cairo, where a
# cross build's CC makes programs for another; dpkg-buildflags gives the
# _FOR_BUILD flags, and a native build is as before)
CC_FOR_BUILD ?= $(CC)
CFLAGS_FOR_BUILD ?= $(CFLAGS)
CPPFLAGS_FOR_BUILD ?= $(CPPFLAGS)
LDFLAGS_FOR_BUILD ?= $(LDFLAGS)
PKG_CONFIG_FOR_BUILD ?= $(PKG_CONFIG)
$(BUILD)/make-picture: tools/make-picture.c | $(BUILD)/obj
	$(CC_FOR_BUILD) $(WARN) $(CFLAGS_FOR_BUILD) -D_POSIX_C_SOURCE=200809L \
	  $(shell $(PKG_CONFIG_FOR_BUILD) --cflags cairo 2>/dev/null) $(CPPFLAGS_FOR_BUILD) $< -o $@ \
	  $(LDFLAGS_FOR_BUILD) $(shell $(PKG_CONFIG_FOR_BUILD) --libs cairo 2>/dev/null) -lm

$(PICTURE): $(BUILD)/make-picture
	$(BUILD)/make-picture $@

# The parameter reference is generated from the table the reader uses.
docs: bin/linewise
	{ sed '/^## \[/,$$d' docs/PARAMETERS.md; bin/linewise params | sed 1d; } > docs/PARAMETERS.md.new
	mv docs/PARAMETERS.md.new docs/PARAMETERS.md
	{ sed '/^| schedule |/,$$d' docs/SCHEDULES.md | sed '$$d'; bin/linewise schedules; } > docs/SCHEDULES.md.new
	mv docs/SCHEDULES.md.new docs/SCHEDULES.md

# The benchmark: tools/bench*.c with the shared pieces in tools/benchutil.c and
# the two-curve reference of the tests (tests/pairref.h).
BENCH_SRC := tools/bench.c tools/bench-accuracy.c tools/bench-order.c tools/bench-regularity.c tools/bench-siman.c tools/bench-tempering.c tools/bench-domains.c tools/bench-tone.c tools/bench-nurbs.c tools/bench-quench.c tools/bench-transdim.c tools/bench-kink.c tools/bench-photo.c tools/benchutil.c
BENCH_HDR := tools/benchutil.h tests/pairref.h tests/testutil.h $(wildcard include/linewise/*.h)
TOOL_FLAGS = $(WARN) $(CFLAGS) $(OMP) $(LW_CPPFLAGS) $(CPPFLAGS) -Itools -Itests

$(BUILD)/bench: $(BENCH_SRC) $(BENCH_HDR) $(BUILD)/liblinewise.a
	$(CC) $(TOOL_FLAGS) -DBENCH_CFLAGS='"$(CFLAGS)"' $(BENCH_SRC) -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) $(LW_LDLIBS)

# Benchmarks rewrite docs/PERFORMANCE.md and docs/ACCURACY.md (machine and date
# recorded with them) and their plots docs/*.png; BENCH_QUICK=1 for a smoke run.
bench: $(BUILD)/bench $(BIN)/linewise $(BUILD)/make-picture $(MPI_BIN)
	mkdir -p $(BUILD)/bench-data
	LW_MPI_BIN=$(MPI_BIN) LW_BIN=$(BIN)/linewise LW_MAKE_PICTURE=$(BUILD)/make-picture \
	  $(BUILD)/bench docs $(BUILD)/bench-data
	gnuplot -e "data='$(BUILD)/bench-data'; out='docs'" tools/bench.gp

# The elastic wire of the D-NURBS review: its Figures 8 and 9 as
# docs/nurbs-figure8.png and docs/nurbs-figure9.png (docs/NURBS.md).
WIRE_DATA := $(BUILD)/wire-data
$(BUILD)/wire-midpoint: tools/wire-midpoint.c $(BUILD)/liblinewise.a
	$(CC) $(TOOL_FLAGS) $< -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) $(LW_LDLIBS)

wire-figures: $(BUILD)/wire-midpoint
	mkdir -p $(WIRE_DATA)
	$(BUILD)/wire-midpoint params/wire.ini 20 > $(WIRE_DATA)/gamma0.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 dynamics.gamma=5 > $(WIRE_DATA)/gamma5.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 dynamics.integrator=review > $(WIRE_DATA)/gamma0-review.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 dynamics.gamma=5 dynamics.integrator=review > $(WIRE_DATA)/gamma5-review.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 nurbs.alpha=10 > $(WIRE_DATA)/alpha10.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 nurbs.alpha=100 > $(WIRE_DATA)/alpha100.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 nurbs.beta=1 > $(WIRE_DATA)/beta1.dat
	$(BUILD)/wire-midpoint params/wire.ini 20 nurbs.beta=50 dynamics.dt=0.004 > $(WIRE_DATA)/beta50.dat
	gnuplot -e "data='$(WIRE_DATA)'; out='docs'" tools/wire-figures.gp

# The scenes with what they read (pictures, the states of init.from), the
# tools, the man page, README and docs/; linewise-mpi where mpicc is (built
# here, never an older one left in bin/).
# The library, its headers and linewise.pc too, for a program that embeds it
# (C or C++: `pkg-config --cflags --libs linewise`).  linewise.pc finds the
# prefix from where it lies, so a copy installed under DESTDIR, or moved, is
# found with PKG_CONFIG_PATH alone (--define-variable=prefix= would move
# cairo's and GSL's paths with it).
# The files install writes, each by its name: uninstall removes those and
# then the folders left empty (it removed share/linewise whole, with a
# scene the user had saved beside the bundled ones).
INSTALLED := bin/linewise bin/linewise-mpi $(TOOLS:%=bin/linewise-%) bin/linewise-animate \
             $(patsubst %,share/linewise/params/%,$(notdir $(wildcard params/*.ini params/*.lw params/*.txt) $(PICTURE))) \
             share/linewise/slurm-sweep.sbatch share/linewise/slurm-tempering.sbatch \
             $(patsubst %,share/doc/linewise/%,README.md $(wildcard docs/*.md docs/*.png) embed.cpp) \
             share/man/man1/linewise.1 share/man/man1/linewise-mpi.1 $(TOOLS:%=share/man/man1/linewise-%.1) \
             share/man/man1/linewise-animate.1 $(LIBDIR)/liblinewise.a $(LIBDIR)/pkgconfig/linewise.pc \
             $(wildcard include/linewise/*.h)
INSTALLED_DIRS := share/linewise/params share/linewise share/doc/linewise/docs share/doc/linewise include/linewise
LW_VERSION := $(shell sed -n 's/^\#define LW_VERSION "\(.*\)"/\1/p' include/linewise/version.h)
# The install's root, quoted for the shell: a DESTDIR or PREFIX with a blank
# stays one path (unquoted, uninstall removed the directory before the blank),
# and one with ` or " is taken as it is (single quotes, a ' in it escaped); a
# $ is make's own, as everywhere in a make variable (write $$).
shell_quote = '$(subst ','\'',$(1))'
D = $(call shell_quote,$(DESTDIR)$(PREFIX))
# linewise.pc's way up from $(LIBDIR)/pkgconfig to the prefix: ../.. for lib
PC_UP := $(shell printf '%s' '$(LIBDIR)' | sed 's,[^/][^/]*,..,g')/..
# (an absolute one, as GNU's libdir, went under PREFIX twice unsaid, and a .
# or .. made linewise.pc point beside the headers)
check_libdir = case '$(LIBDIR)' in '' | /* | . | .. | ./* | ../* | */. | */.. | */./* | */../*) \
  echo "LIBDIR=$(LIBDIR): expected a folder under PREFIX, as lib or lib/x86_64-linux-gnu (no leading /, . or ..)" >&2; \
  exit 2 ;; esac
# (the files a redirection writes take the umask, 077 a root's on many a
# shared machine: chmod makes them every user's, as install -m does)
install: $(BIN)/linewise $(PICTURE) $(MPI_BIN) $(BUILD)/liblinewise.a
	@$(check_libdir)
	install -d $(D)/bin $(D)/share/linewise/params $(D)/share/doc/linewise/docs
	install -d $(D)/$(LIBDIR)/pkgconfig $(D)/include/linewise $(D)/share/man/man1
	install -m 644 $(BUILD)/liblinewise.a $(D)/$(LIBDIR)/
	install -m 644 include/linewise/*.h $(D)/include/linewise/
	printf '%s\n' 'prefix=$${pcfiledir}/$(PC_UP)' 'libdir=$${prefix}/$(LIBDIR)' 'includedir=$${prefix}/include' '' \
	  'Name: linewise' 'Description: elastic Bezier curves annealed into line art (the library of linewise)' \
	  'Version: $(LW_VERSION)' 'Requires: $(PKGS)' 'Libs: -L$${libdir} -llinewise -fopenmp -lm' \
	  'Cflags: -I$${includedir}' > $(D)/$(LIBDIR)/pkgconfig/linewise.pc
	chmod 644 $(D)/$(LIBDIR)/pkgconfig/linewise.pc
	install -m 755 $(BIN)/linewise $(MPI_BIN) $(D)/bin/
	install -m 644 params/*.ini params/*.lw params/*.txt $(PICTURE) $(D)/share/linewise/params/
	install -m 644 docs/linewise.1 $(D)/share/man/man1/linewise.1
	if [ -n '$(MPI_BIN)' ]; then echo '.so man1/linewise.1' > $(D)/share/man/man1/linewise-mpi.1 && \
	  chmod 644 $(D)/share/man/man1/linewise-mpi.1; fi
	for t in $(TOOLS); do install -m 755 tools/$$t $(D)/bin/linewise-$$t || exit 1; done
	install -m 755 tools/animate.sh $(D)/bin/linewise-animate
	# each tool's man page: its line of tools/whatis, then its --help as it is
	for t in $(TOOLS) animate; do \
	  what=$$(sed -n "s/^$$t: //p" tools/whatis); \
	  test -n "$$what" || { echo "tools/whatis: no line for $$t" >&2; exit 1; }; \
	  help=$$($(D)/bin/linewise-$$t --help) || { echo "linewise-$$t --help failed" >&2; exit 1; }; \
	  { printf '.TH LINEWISE-%s 1 "" "linewise $(LW_VERSION)"\n.SH NAME\nlinewise-%s \\- %s\n.SH SYNOPSIS\n.nf\n' \
	      "$$(echo $$t | tr a-z A-Z)" "$$t" "$$what"; \
	    printf '%s\n' "$$help" | sed 's/\\/\\e/g; s/^[.'"'"']/\\\&&/'; \
	    printf '.fi\n.SH SEE ALSO\n.BR linewise (1),\nREADME.md in %s/share/doc/linewise.\n' \
	      "$$(printf '%s' $(call shell_quote,$(PREFIX)) | sed 's/\\/\\e/g')"; \
	  } > $(D)/share/man/man1/linewise-$$t.1 && chmod 644 $(D)/share/man/man1/linewise-$$t.1 || exit 1; done
	install -m 644 tools/slurm-sweep.sbatch tools/slurm-tempering.sbatch $(D)/share/linewise/
	# (docs/ beside README, as in the source: README's links are to docs/X.md)
	install -m 644 README.md tests/embed.cpp $(D)/share/doc/linewise/
	install -m 644 docs/*.md docs/*.png $(D)/share/doc/linewise/docs/

uninstall:
	@$(check_libdir)
	n=0; for f in $(INSTALLED); do if [ -e $(D)/$$f ]; then rm -f $(D)/$$f || exit 1; n=$$((n + 1)); fi; done; \
	  [ $$n -gt 0 ] || echo "uninstall: no file of linewise's in $(D) (installed with another PREFIX?)" >&2
	# (a folder that holds nothing but a kept one is not said again)
	root=$(D); kept=; for d in $(INSTALLED_DIRS); do if [ -d "$$root/$$d" ] && ! rmdir "$$root/$$d" 2>/dev/null; then \
	  own=; for e in "$$root/$$d"/* "$$root/$$d"/.[!.]*; do [ -e "$$e" ] || [ -L "$$e" ] || continue; \
	    case " $$kept " in *" $${e#"$$root/"} "*) ;; *) own=1 ;; esac; done; \
	  [ -z "$$own" ] || echo "uninstall: $$d kept: files not installed are in it" >&2; kept="$$kept $$d"; fi; done

clean:
	rm -rf build build-asan build-fuzz bin $(PICTURE)

# the headers each object was built from (DEPFLAGS); an object without its
# .d (built before them, or the .d lost) depends on every header, as all did
# before.  (Not the .d itself as a prerequisite: clang writes it after the
# object, which then always looked out of date.)
DEP_FILES := $(LIB_OBJ:.o=.d) $(TEST_SRC:tests/%.c=$(BUILD)/tests/%.d) $(FUZZ_REPLAY_OBJ:.o=.d) $(FUZZ_OBJ:.o=.d)
ALL_HEADERS := $(wildcard include/linewise/*.h tests/*.h tests/fuzz/*.h)
$(foreach d,$(DEP_FILES),$(if $(wildcard $(d)),,$(eval $(d:.d=.o): $(ALL_HEADERS))))
-include $(wildcard $(DEP_FILES))
