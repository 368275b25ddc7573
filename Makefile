# fdemd build. Sources are found by folder, so adding a file needs no edit here.
#
#   make            bin/fdemd and bin/fdemctl (installs missing Debian packages first)
#   make test       unit tests, then integration tests against the real daemon
#   make test-san   the same under AddressSanitizer + UndefinedBehaviorSanitizer
#   make bench      speed and memory figures (never part of the tests)
#   make demo       start a daemon, run a bundled example end to end, draw a PNG
#   make limits     the mesh-dependence figures of docs/physics.md (minutes; not a test)
#
# SAN=1 builds everything instrumented into build-san/ and bin-san/.

CC      ?= cc
PYTHON  := /usr/bin/python3
PKGS    := libmicrohttpd jansson hdf5 libcurl zlib

ifeq ($(SAN),1)
BUILD   := build-san
BIN     := bin-san
OPT     := -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
LDSAN   := -fsanitize=address,undefined
# unit tests whose full-size run takes minutes under ASan run a smaller
# case when this is set, where the normal build checks the full one
TESTSAN := -DFDEM_SAN
else
BUILD   := build
BIN     := bin
OPT     := -O2 -g
LDSAN   :=
TESTSAN :=
# The tetrahedron contact kernel clips and splits polygons of 3-5 vertices
# in short loops; -O3 unrolls and specialises them: 6.6 % fewer
# instructions for the whole sphere-pile step, the same bits (IEEE
# arithmetic in the same order, no contraction under -std=c11).
$(BUILD)/core/kernel/contact_tet.o: OPT += -O3
# The shut-joint kernels (contact_face*.c) loop over 3-4 corners by index:
# -O3 unrolls them: a broken 3D block's role_force took 600 instructions a
# call at -O2, 295 at -O3 (callgrind); the same bits (no contraction)
$(BUILD)/core/kernel/contact_face.o $(BUILD)/core/kernel/contact_face_tet.o \
$(BUILD)/core/kernel/contact_face_tri.o: OPT += -O3
endif

WARN    := -Wall -Wextra -Werror -Wshadow -Wno-unused-parameter
CSTD    := -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
CFLAGS  += $(CSTD) $(OPT) $(WARN) -MMD -MP
PKG_CFLAGS = $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS   = $(shell pkg-config --libs $(PKGS) 2>/dev/null)

CORE_SRC   := $(wildcard core/*.c core/*/*.c)
PROTO_SRC  := $(wildcard proto/*.c proto/*/*.c)
SERVER_SRC := $(wildcard server/*.c server/*/*.c)
# runner/: the batch loop (a library) and the mains of bin/fdem-run and,
# where mpicc exists, bin/fdem-rank (MPI lives only in runner/mpi and there)
RUNNER_SRC := $(filter-out runner/fdem_%_main.c,$(wildcard runner/*.c))
RANK_SRC   := runner/fdem_rank_main.c
MPICC      := $(shell command -v mpicc 2>/dev/null)
CTL_SRC    := $(wildcard clients/fdemctl/*.c)
UNIT_SRC   := $(wildcard tests/unit/test_*.c)
BENCH_SRC  := $(wildcard bench/*.c)
FUZZ_SRC   := $(wildcard tests/fuzz/*.c)

CORE_OBJ   := $(CORE_SRC:%.c=$(BUILD)/%.o)
PROTO_OBJ  := $(PROTO_SRC:%.c=$(BUILD)/%.o)
SERVER_OBJ := $(SERVER_SRC:%.c=$(BUILD)/%.o)
RUNNER_OBJ := $(RUNNER_SRC:%.c=$(BUILD)/%.o)
RANK_OBJ   := $(RANK_SRC:%.c=$(BUILD)/mpi-%.o)
RANK_ENGINE_OBJ := $(patsubst runner/mpi/%.c,$(BUILD)/rank-engine/%.o,$(wildcard runner/mpi/*.c))
CTL_OBJ    := $(CTL_SRC:%.c=$(BUILD)/%.o)
UNIT_BIN   := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)

LIBCORE    := $(BUILD)/libfdemcore.a
LIBPROTO   := $(BUILD)/libfdemproto.a
LIBRUNNER  := $(BUILD)/libfdemrunner.a
RANK_BIN   := $(if $(MPICC),$(BIN)/fdem-rank)

.PHONY: all deps test test-unit test-integration test-san bench demo limits estimates web-figures fuzz clean

all: deps $(BIN)/fdemd $(BIN)/fdemctl $(BIN)/fdem-run $(RANK_BIN)
ifeq ($(MPICC),)
	@echo "mpicc not found: bin/fdem-rank not built (ranked cases need openmpi-bin libopenmpi-dev)"
endif

# Installs what is missing (apt-get) once; a stamp keeps later runs quiet.
deps: $(BUILD)/.deps
$(BUILD)/.deps: scripts/install-deps.sh
	@mkdir -p $(BUILD)
	@bash scripts/install-deps.sh
	@touch $@

$(BUILD)/core/%.o: core/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Icore -fopenmp -c $< -o $@
$(BUILD)/proto/%.o: proto/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Icore -Iproto -c $< -o $@
$(BUILD)/server/%.o: server/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Icore -Iproto -Iserver -Irunner -c $< -o $@
$(BUILD)/runner/%.o: runner/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Icore -Iproto -Irunner -c $< -o $@
$(BUILD)/mpi-runner/%.o: runner/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(MPICC) $(CFLAGS) $(PKG_CFLAGS) $(if $(wildcard runner/mpi/*.c),-DFDEM_RANK_ENGINE) -Icore -Iproto -Irunner -fopenmp -c $< -o $@
$(BUILD)/clients/%.o: clients/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -c $< -o $@

$(LIBCORE): $(CORE_OBJ)
	@rm -f $@
	ar rcs $@ $^
$(LIBPROTO): $(PROTO_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(LIBRUNNER): $(RUNNER_OBJ)
	@rm -f $@
	ar rcs $@ $^
$(BIN)/fdemd: $(SERVER_OBJ) $(LIBRUNNER) $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(BIN)
	$(CC) $(LDSAN) -fopenmp -o $@ $(SERVER_OBJ) $(LIBRUNNER) $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lpthread -lm
$(BIN)/fdem-run: $(BUILD)/runner/fdem_run_main.o $(LIBRUNNER) $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(BIN)
	$(CC) $(LDSAN) -fopenmp -o $@ $< $(LIBRUNNER) $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lpthread -lm
$(BIN)/fdem-rank: $(RANK_OBJ) $(RANK_ENGINE_OBJ) $(LIBRUNNER) $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(BIN)
	$(MPICC) $(LDSAN) -fopenmp -o $@ $(RANK_OBJ) $(RANK_ENGINE_OBJ) $(LIBRUNNER) $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) $(if $(RANK_ENGINE_OBJ),-lmetis) -lpthread -lm
$(BIN)/fdemctl: $(CTL_OBJ)
	@mkdir -p $(BIN)
	$(CC) $(LDSAN) -o $@ $(CTL_OBJ) $(PKG_LIBS) -lm

# Unit tests link everything below the server (runner/ too); each file is one binary.
$(BUILD)/tests/%: tests/unit/%.c tests/unit/check.h $(LIBRUNNER) $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(TESTSAN) $(PKG_CFLAGS) -Icore -Iproto -Irunner -Itests/unit $(LDSAN) -fopenmp -o $@ $< \
	    $(LIBRUNNER) $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lpthread -lm

$(BUILD)/bench/%: bench/%.c $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -O3 -march=native $(PKG_CFLAGS) -Icore -Iproto $(LDSAN) -fopenmp -o $@ $< \
	    $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lpthread -lm

$(BUILD)/scripts/%: scripts/%.c $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(PKG_CFLAGS) -Icore -Iproto $(LDSAN) -fopenmp -o $@ $< \
	    $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lpthread -lm

# MPI (issue 37): runner/mpi and the programs that link it build with
# mpicc, only where it exists; elsewhere they are left out with a message.
MPI_TESTS  := $(if $(MPICC),$(BUILD)/tests/mpi/rank_compare)
MPI_LINK    = $(MPICC) $(CFLAGS) $(PKG_CFLAGS) -Icore -Iproto -Irunner -Itests/unit $(LDSAN) -fopenmp -o $@ $< \
              $(RANK_ENGINE_OBJ) $(LIBPROTO) $(LIBCORE) $(PKG_LIBS) -lmetis -lpthread -lm
$(BUILD)/rank-engine/%.o: runner/mpi/%.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(MPICC) $(CFLAGS) -Icore -Iproto -Irunner -c $< -o $@
$(BUILD)/tests/mpi/%: tests/mpi/%.c $(RANK_ENGINE_OBJ) $(LIBPROTO) $(LIBCORE)
	@mkdir -p $(dir $@)
	$(MPI_LINK)
.PHONY: mpi mpi-missing test-ranks
.SECONDARY: $(RANK_ENGINE_OBJ)
$(BUILD)/bench/mpi/%: bench/mpi/%.c $(LIBCORE)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -O3 -Icore -fopenmp -o $@ $< $(LIBCORE) -lmetis -lm
# make bench runs bench/mpi/run.sh after the others when these exist
bench: $(if $(MPICC),$(MPI_TESTS) $(BUILD)/bench/mpi/bench_partition)
# the rank engine's same-bits test with 8 ranks too (minutes on a loaded
# machine, so not in make test)
test-ranks: mpi all
	@FDEM_RANKS_FULL=1 FDEMD_BIN=$(BIN)/fdemd FDEMCTL_BIN=$(BIN)/fdemctl $(PYTHON) tests/integration/run.py 'test_ranks.py'
mpi: $(if $(MPICC),$(MPI_TESTS),mpi-missing)
mpi-missing:
	@echo "mpicc not found: the MPI rank engine is not built (scripts/install-deps.sh installs it)"

test: all $(UNIT_BIN) mpi
	@BUILD=$(BUILD) BIN=$(BIN) PYTHON=$(PYTHON) bash tests/run_tests.sh

test-unit: deps $(UNIT_BIN) mpi
	@BUILD=$(BUILD) BIN=$(BIN) PYTHON=$(PYTHON) UNIT_ONLY=1 bash tests/run_tests.sh

test-san:
	$(MAKE) SAN=1 test

bench: deps $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%) $(BIN)/fdemd
	@BUILD=$(BUILD) BIN=$(BIN) PYTHON=$(PYTHON) bash bench/run.sh

demo: all
	@BIN=$(BIN) PYTHON=$(PYTHON) bash scripts/demo.sh

limits: deps $(BUILD)/scripts/limits
	@LIMITS=$(BUILD)/scripts/limits $(PYTHON) scripts/limits.py

# estimated_seconds against the measured run of every bundled example, and
# eta against the clock: wall-time figures for a quiet machine (minutes), so
# not part of make test (tests/integration/test_estimate.py)
estimates: all
	@FDEMD_ESTIMATES=1 FDEMD_BIN=$(BIN)/fdemd FDEMCTL_BIN=$(BIN)/fdemctl $(PYTHON) tests/integration/run.py 'test_estimate.py'

# how long a 1e5-element 2D and 3D snapshot takes to show in the page
# (headless Chromium; issue 35): minutes, so not part of make test
web-figures: all
	@cd tests/integration && FDEMD_WEB_FIGURES=1 FDEMD_BIN=$(CURDIR)/$(BIN)/fdemd \
	    FDEMCTL_BIN=$(CURDIR)/$(BIN)/fdemctl $(PYTHON) -m unittest -v test_web_figures

fuzz: deps
	@bash tests/fuzz/run.sh

clean:
	rm -rf build build-san bin bin-san

-include $(shell find build build-san -name '*.d' 2>/dev/null)
