# linewise -- elastic Bezier curves annealed into line art.
# Targets: all (bin/linewise), deps, test, asan, run, bench, install, clean.

CC      ?= cc
PREFIX  ?= /usr/local
BUILD   ?= build
BIN     ?= bin
PKGS    := gsl cairo inih
OPT     ?= -O2
CFLAGS  ?= $(OPT) -g
WARN    := -std=c11 -Wall -Wextra -Wshadow -Wstrict-prototypes -Wno-unused-parameter
CPPFLAGS += -Iinclude -D_POSIX_C_SOURCE=200809L $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
LDLIBS  += $(shell pkg-config --libs $(PKGS) 2>/dev/null) -lm
OMP     := -fopenmp

DEBS    := build-essential pkg-config libgsl-dev libcairo2-dev libinih-dev libstb-dev \
           libcriterion-dev gnuplot-nox

LIB_SRC := $(filter-out src/main.c,$(wildcard src/*.c))
LIB_OBJ := $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o)
TEST_SRC := $(wildcard tests/test_*.c)
TEST_OBJ := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%.o)
TEST_JOBS ?= 2

.PHONY: all deps test asan run bench install clean docs
all: $(BIN)/linewise

$(BUILD)/obj/%.o: src/%.c $(wildcard include/linewise/*.h) | $(BUILD)/obj
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(CPPFLAGS) -c $< -o $@

$(BUILD)/liblinewise.a: $(LIB_OBJ)
	rm -f $@ && ar rcs $@ $^

$(BIN)/linewise: src/main.c $(BUILD)/liblinewise.a | $(BIN)
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(CPPFLAGS) $< -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS)

$(BUILD)/tests/%.o: tests/%.c $(wildcard tests/*.h) $(wildcard include/linewise/*.h) | $(BUILD)/tests
	$(CC) $(WARN) $(CFLAGS) $(OMP) $(CPPFLAGS) -Itests -c $< -o $@

$(BUILD)/tests/run: $(TEST_OBJ) $(BUILD)/liblinewise.a
	$(CC) $(CFLAGS) $(OMP) $(TEST_OBJ) -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS) -lcriterion

$(BUILD)/obj $(BUILD)/tests $(BIN):
	mkdir -p $@

# The suite runs the binary too (CLI tests), so both are built first.
test: $(BIN)/linewise $(BUILD)/tests/run
	LW_BIN=$(CURDIR)/$(BIN)/linewise LW_ROOT=$(CURDIR) $(BUILD)/tests/run --jobs $(TEST_JOBS)

asan:
	$(MAKE) BUILD=build-asan BIN=build-asan/bin OPT=-O1 \
	  CFLAGS="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer" \
	  LDFLAGS="-fsanitize=address,undefined" test

deps:
	@missing=""; for p in $(DEBS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; \
	else echo "all build dependencies present"; fi

run: bin/linewise
	bin/linewise run params/example.ini --out out/example

# The parameter reference is generated from the table the reader uses.
docs: bin/linewise
	{ sed '/^## \[/,$$d' docs/PARAMETERS.md; bin/linewise params | sed 1d; } > docs/PARAMETERS.md.new
	mv docs/PARAMETERS.md.new docs/PARAMETERS.md
	{ sed '/^| schedule |/,$$d' docs/SCHEDULES.md | sed '$$d'; bin/linewise schedules; } > docs/SCHEDULES.md.new
	mv docs/SCHEDULES.md.new docs/SCHEDULES.md

# The benchmark: tools/bench*.c with the shared pieces in tools/benchutil.c and
# the two-curve reference of the tests (tests/pairref.h).
BENCH_SRC := tools/bench.c tools/bench-accuracy.c tools/bench-siman.c tools/benchutil.c
BENCH_HDR := tools/benchutil.h tests/pairref.h tests/testutil.h $(wildcard include/linewise/*.h)
TOOL_FLAGS = $(WARN) $(CFLAGS) $(OMP) $(CPPFLAGS) -Itools -Itests

$(BUILD)/bench: $(BENCH_SRC) $(BENCH_HDR) $(BUILD)/liblinewise.a
	$(CC) $(TOOL_FLAGS) -DBENCH_CFLAGS='"$(CFLAGS)"' $(BENCH_SRC) -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS)

$(BUILD)/pair-accuracy: tools/pair-accuracy.c tools/benchutil.c $(BENCH_HDR) $(BUILD)/liblinewise.a
	$(CC) $(TOOL_FLAGS) tools/pair-accuracy.c tools/benchutil.c -o $@ $(BUILD)/liblinewise.a $(LDFLAGS) $(LDLIBS)

# Benchmarks rewrite docs/PERFORMANCE.md and docs/ACCURACY.md (machine and date
# recorded with them) and their plots docs/*.png; BENCH_QUICK=1 for a smoke run.
bench: $(BUILD)/bench
	mkdir -p $(BUILD)/bench-data
	$(BUILD)/bench docs $(BUILD)/bench-data
	gnuplot -e "data='$(BUILD)/bench-data'; out='docs'" tools/bench.gp

install: $(BIN)/linewise
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/share/linewise/params
	install -m 755 bin/linewise $(DESTDIR)$(PREFIX)/bin/linewise
	install -m 644 params/*.ini $(DESTDIR)$(PREFIX)/share/linewise/params/
	install -d $(DESTDIR)$(PREFIX)/share/man/man1
	install -m 644 docs/linewise.1 $(DESTDIR)$(PREFIX)/share/man/man1/linewise.1

clean:
	rm -rf build build-asan bin
