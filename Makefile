# undulate — one hand-written Makefile.
#
# Layout convention (keeps this file stable as modules grow):
#   every component directory holds one program's `main.c` and any number of
#   other .c files; the other files form a static library that unit tests link
#   against, so a test can exercise a module without the program's main().
#
#   make            build everything into $(BUILD)/
#   make test       install missing packages, build, run every test
#   make test-long  the long sweeps (paper experiments over many separations)
#   make test-busy  make test with one CPU-bound process per core beside it
#   make bench      benchmarks; figures printed, written to $(BUILD)/bench.md
#   make demo       robots on the simulated bus, watched live
#   make figures    the paper's figures from the real daemons in lockstep:
#                   docs/FIGURES.md and docs/figures/ (QUICK=1: fewer runs;
#                   FIGURES_ARGS='--only pair --jobs 3': scripts/figures.sh's options)
#   make golden     the golden runs (tests/golden/): run, show what changed,
#                   rewrite their expectations (GOLDEN_ARGS='pair_anti': one;
#                   scripts/golden.sh without --update only compares)
#   make hwcheck PORT=/dev/ttyUSB0 [CONFIG=robot.conf] [IDS="1 2"]
#                   the first-run hardware check on a robot (dxl doctor)
#   make SAN=1 test the same tests under AddressSanitizer + UBSan (build-san/)
#   make fuzz       libFuzzer target for the packet parser (needs clang)
#   make test-sdk DXL_SDK=DIR
#                   ROBOTIS's DynamixelSDK (a checkout of it, built outside this
#                   tree) as a client of the simulator, Protocol 1.0 and 2.0

SAN      ?=
ifeq ($(SAN),1)
BUILD    ?= build-san
SANFLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
else
BUILD    ?= build
SANFLAGS :=
endif

CC       ?= cc
PREFIX   ?= /usr/local
DESTDIR  ?=
BIN      := $(BUILD)/bin
OBJ      := $(BUILD)/obj
LIB      := $(BUILD)/lib
GEN      := $(BUILD)/lcmgen

# liblzma: undulate-analyze reads the xz-compressed logs make demo keeps
PKGS     := lcm libserialport inih libsodium liblzma
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS   := $(shell pkg-config --libs $(PKGS) 2>/dev/null)

WARN     := -Wall -Wextra -Wshadow -Wmissing-prototypes -Wstrict-prototypes \
            -Wpointer-arith -Wcast-qual -Wundef -Wvla -Wformat-security -Werror
STD      := -std=c11 -D_DEFAULT_SOURCE -D_XOPEN_SOURCE=700
OPT      ?= -O2 -g
CPPFLAGS += -I. -Icommon -Iprotocol -Iprotocol/io -I$(GEN) -MMD -MP
CFLAGS   += $(STD) $(OPT) $(SANFLAGS) $(PKG_CFLAGS)
LDFLAGS  += $(SANFLAGS)
LDLIBS   += $(PKG_LIBS) -lm

# lcm-gen output is not ours: compile it without our warning set, and with
# compat/ first on its include path (decoders that check every length and
# allocate through compat/lcm/lcmdec.c, which is ours and joins the library).
GEN_WARN := -w

# ---- components -------------------------------------------------------------
# name : directory
# bench/ holds standalone programs compiled by bench/run.sh, not a library.
COMPONENTS := common protocol daemon sim dxl top analyze web model
DIR_common   := common
DIR_protocol := protocol protocol/io
DIR_daemon   := daemon
DIR_sim      := sim-bridge
DIR_dxl      := tools/dxl
DIR_top      := tools/top
DIR_analyze  := tools/analyze
DIR_web      := tools/web
DIR_model    := model

# programs: binary name -> component, and the libraries each links (in order)
PROG_undulated        := daemon
PROG_undulate-sim     := sim
PROG_dxl              := dxl
PROG_undulate-top     := top
PROG_undulate-analyze := analyze
PROG_undulate-web     := web
PROG_undulate-model   := model
ALL_PROGRAMS := undulated undulate-sim dxl undulate-top undulate-analyze undulate-web undulate-model
# Build only programs whose main.c exists (keeps partial trees buildable).
PROGRAMS := $(foreach p,$(ALL_PROGRAMS),$(if $(wildcard $(firstword $(DIR_$(PROG_$(p))))/main.c),$(p)))
DEPS_daemon   := daemon protocol common
DEPS_sim      := sim protocol common
# dxl doctor reads undulated's configuration and runs its cycle: libdaemon
DEPS_dxl      := dxl daemon protocol common
DEPS_top      := top protocol common
DEPS_analyze  := analyze protocol common
# undulate-web: top's model (the LCM picture, top_json), analyze's end-state
# rules, the daemon's command validation
DEPS_web      := web top analyze daemon protocol common
# undulate-model: the analyser's end-state rules (classify.c) and theory
# (theory.c) for its summary, so that its pairs are named as a log's are
DEPS_model    := model analyze common
DEPS_protocol := protocol common
DEPS_common   := common

srcs_of   = $(foreach d,$(DIR_$(1)),$(wildcard $(d)/*.c))
libsrcs_of = $(filter-out %/main.c,$(call srcs_of,$(1)))
objs      = $(patsubst %.c,$(OBJ)/%.o,$(1))
libs_of   = $(foreach c,$(DEPS_$(1)),$(LIB)/lib$(c).a)

# ---- lcmtypes ---------------------------------------------------------------
LCM_SRC  := $(wildcard lcmtypes/*.lcm)
LCM_STAMP := $(GEN)/.stamp
# lcm-gen names files <package>_<type>.c; the package is `undulate`.
LCM_GEN_C = $(wildcard $(GEN)/*.c)

.PHONY: all deps test-deps test test-long test-busy test-sdk bench demo figures golden hwcheck fuzz spy-jar spy install uninstall clean lcmtypes
all: $(foreach p,$(PROGRAMS),$(BIN)/$(p)) unit-tests

$(LCM_STAMP): $(LCM_SRC)
	@mkdir -p $(GEN)
	@rm -f $(GEN)/*.c $(GEN)/*.h
	lcm-gen -c --c-cpath $(GEN) --c-hpath $(GEN) $(LCM_SRC)
	@touch $@
lcmtypes: $(LCM_STAMP)

# The generated file list is only known after lcm-gen ran: build the library
# through a recursive step so the wildcard is evaluated afterwards.
LCM_COMPAT := compat/lcm/lcm_coretypes.h
LCMDEC_OBJ := $(OBJ)/compat/lcm/lcmdec.o
$(LIB)/liblcmtypes.a: $(LCM_STAMP) $(LCM_COMPAT) $(LCMDEC_OBJ)
	@$(MAKE) --no-print-directory lcmtypes-lib

.PHONY: lcmtypes-lib
lcmtypes-lib:
	@mkdir -p $(OBJ)/lcmgen $(LIB)
	@set -e; for c in $(GEN)/*.c; do \
	  o=$(OBJ)/lcmgen/$$(basename $$c .c).o; \
	  if [ ! -f $$o ] || [ $$c -nt $$o ] || [ $(LCM_COMPAT) -nt $$o ]; then \
	    echo "CC (lcm-gen) $$c"; \
	    $(CC) $(STD) $(OPT) $(SANFLAGS) $(PKG_CFLAGS) -Icompat -I$(GEN) $(GEN_WARN) -c $$c -o $$o; \
	  fi; \
	done; \
	rm -f $(LIB)/liblcmtypes.a; ar rcs $(LIB)/liblcmtypes.a $(OBJ)/lcmgen/*.o $(LCMDEC_OBJ)

# ---- objects and libraries --------------------------------------------------
$(OBJ)/%.o: %.c $(LCM_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) $(WARN) -c $< -o $@

define component_lib
$(LIB)/lib$(1).a: $(call objs,$(call libsrcs_of,$(1)))
	@mkdir -p $(LIB)
	@rm -f $$@
	ar rcs $$@ $$^
endef
$(foreach c,$(COMPONENTS),$(eval $(call component_lib,$(c))))

# The protocol framing must stay pure: no I/O, no clock (protocol/README.md).
.PHONY: check-pure
check-pure:
	@! grep -nE '#include <(unistd|libserialport|time|poll|fcntl|termios)\.h>|clock_gettime' protocol/*.c protocol/*.h \
	  || { echo "protocol/ framing must not do I/O or read a clock (use protocol/io/)"; exit 1; }

# Every program decodes LCM messages through compat/lcm/lcmdec.h (bounded,
# checked): lcm-gen's own _decode and _subscribe trust every length.
.PHONY: check-lcmdec
check-lcmdec:
	@! grep -rnE 'undulate_[a-z0-9_]+_t_(decode|subscribe)\(' common daemon protocol sim-bridge tools bench --include='*.c' \
	  || { echo "decode LCM messages with lcmdec_decode() (compat/lcm/lcmdec.h), not lcm-gen's _decode/_subscribe"; exit 1; }

define program
$(BIN)/$(1): $(OBJ)/$(firstword $(DIR_$(PROG_$(1))))/main.o $(call libs_of,$(PROG_$(1))) $(LIB)/liblcmtypes.a
	@mkdir -p $(BIN)
	$(CC) $(LDFLAGS) -o $$@ $$< $(call libs_of,$(PROG_$(1))) $(LIB)/liblcmtypes.a $$(LDLIBS)
endef
$(foreach p,$(PROGRAMS),$(eval $(call program,$(p))))

# ---- unit tests ---------------------------------------------------------------
# tests/unit/test_<component>_<what>.c: one cmocka program each, linked against
# that component's libraries (e.g. test_sim_world.c -> libsim.a libprotocol.a).
# tests/unit/*.c not named test_* are shared helpers linked into every test.
UNIT_SRC   := $(wildcard tests/unit/test_*.c)
UNIT_BINS  := $(patsubst tests/unit/%.c,$(BUILD)/tests/%,$(UNIT_SRC))
TEST_HELPERS := $(call objs,$(filter-out tests/unit/test_%.c,$(wildcard tests/unit/*.c)))
.PHONY: unit-tests
unit-tests: $(UNIT_BINS)
test_component = $(word 2,$(subst _, ,$(1)))

define unit_test
$(BUILD)/tests/$(1): $(OBJ)/tests/unit/$(1).o $(TEST_HELPERS) $(call libs_of,$(call test_component,$(1))) $(LIB)/liblcmtypes.a
	@mkdir -p $$(dir $$@)
	$(CC) $(LDFLAGS) -o $$@ $$< $(TEST_HELPERS) $(call libs_of,$(call test_component,$(1))) $(LIB)/liblcmtypes.a $$(LDLIBS) -lcmocka
endef
$(foreach t,$(patsubst tests/unit/%.c,%,$(UNIT_SRC)),$(eval $(call unit_test,$(t))))

# tests/tools/*.c: programs the integration tests drive (peers, forgers),
# linked against the daemon's libraries; never installed.
TOOL_SRC  := $(wildcard tests/tools/*.c)
TOOL_BINS := $(patsubst tests/tools/%.c,$(BUILD)/tests/tools/%,$(TOOL_SRC))
$(BUILD)/tests/tools/%: $(OBJ)/tests/tools/%.o $(call libs_of,daemon) $(LIB)/liblcmtypes.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $< $(call libs_of,daemon) $(LIB)/liblcmtypes.a $(LDLIBS)
# undulate-web serves HTTP and WebSocket with libwebsockets (Debian's
# libwebsockets-dev); only it links it.
$(BIN)/undulate-web: LDLIBS += -lwebsockets
# ... and the Foxglove op parser's test (libwebsockets' lejp, tools/web/fox.h)
$(BUILD)/tests/test_web_fox: LDLIBS += -lwebsockets
$(BUILD)/tests/test_web_wlcm: LDLIBS += -lwebsockets
# The simulator's plane world steps Chipmunk2D (Debian's libchipmunk-dev):
# the simulator and its tests link it.
$(BIN)/undulate-sim: LDLIBS += -lchipmunk
$(patsubst tests/unit/%.c,$(BUILD)/tests/%,$(wildcard tests/unit/test_sim_*.c)): LDLIBS += -lchipmunk
# undulate-model integrates the paper's equations with GSL's odeiv2 and finds
# its collisions with GSL's root finders (Debian's libgsl-dev): it and its
# tests link GSL.
$(BIN)/undulate-model: LDLIBS += -lgsl -lgslcblas
$(patsubst tests/unit/%.c,$(BUILD)/tests/%,$(wildcard tests/unit/test_model_*.c)): LDLIBS += -lgsl -lgslcblas
# pngdata reads the plots' PNGs (libpng, from Debian's libpng-dev).
$(BUILD)/tests/tools/pngdata: LDLIBS += -lpng
unit-tests: $(TOOL_BINS)

# ---- entry points -----------------------------------------------------------
deps:
	@scripts/deps.sh

# The tests also want a browser (web_dashboard draws the page in headless
# chromium): installed when it can be, else that check skips and says why.
test-deps: deps
	@scripts/deps.sh chromium || echo "make: chromium not installed: web_dashboard's browser checks will skip"

# DXL_SDK=DIR: a DynamixelSDK checkout; with it `make test` also runs
# tests/integration/sdk_client.sh (without it that test skips and says how).
DXL_SDK ?=
# The build before the tests uses every core unless make was given its own -j
# (then the jobserver it handed down decides).
BUILD_JOBS = $(if $(findstring j,$(filter-out --%,$(MAKEFLAGS))),,-j$(shell nproc 2>/dev/null || echo 2))
test: test-deps
	@$(MAKE) --no-print-directory $(BUILD_JOBS) check-pure check-lcmdec all
	@BUILD=$(BUILD) DXL_SDK=$(DXL_SDK) tests/run.sh

test-sdk: deps
	@$(MAKE) --no-print-directory all
	@test -n "$(DXL_SDK)" || { echo "usage: make test-sdk DXL_SDK=DIR (a checkout of https://github.com/ROBOTIS-GIT/DynamixelSDK)" >&2; exit 2; }
	@BUILD=$(BUILD) DXL_SDK=$(DXL_SDK) TEST_FILTER=sdk_client tests/run.sh

test-long: test-deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) TEST_LONG=1 tests/run.sh

test-busy: test-deps
	@$(MAKE) --no-print-directory check-pure check-lcmdec all
	@scripts/busy.sh env BUILD=$(BUILD) tests/run.sh

bench: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) bench/run.sh

DEMO_SECONDS ?=
DEMO_OUT ?=
demo: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) DEMO_SECONDS=$(DEMO_SECONDS) DEMO_OUT=$(DEMO_OUT) DEMO_COMPRESS=1 scripts/demo.sh

# The paper's figures (scripts/figures.sh, README.md "Figures"): every run
# through GNU parallel here, then docs/FIGURES.md. QUICK=1: the quick set.
QUICK ?=
FIGURES_ARGS ?=
figures: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) scripts/figures.sh $(if $(filter 1,$(QUICK)),--quick) $(FIGURES_ARGS)

# The golden runs (tests/golden/README.md), after a change of behaviour that
# was meant: each run again, every value that changed printed old -> new, and
# tests/golden/NAME.chk rewritten; commit them with the change.
# tests/integration/golden_runs.sh (make test) holds the runs to them.
GOLDEN_ARGS ?=
golden: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) scripts/golden.sh --update $(GOLDEN_ARGS)

# The first command on a new robot: dxl doctor (tools/dxl/README.md). Its
# exit status is make's: 0 all OK, 1 warnings, 7 a check failed.
PORT   ?=
CONFIG ?=
IDS    ?=
hwcheck: $(BIN)/dxl
	@test -n "$(PORT)$(CONFIG)" || { echo "usage: make hwcheck PORT=/dev/ttyUSB0 [CONFIG=robot.conf] [IDS=\"1 2\"]" >&2; exit 2; }
	$(BIN)/dxl doctor $(if $(PORT),--port '$(PORT)') $(if $(CONFIG),--config '$(CONFIG)') $(IDS)

# libFuzzer targets: tests/fuzz/fuzz_<component>_<what>.c, built with clang
# from the sources of that component's libraries (instrumented, unlike the
# gcc-built archives) and run by scripts/fuzz.sh for a fixed number of inputs.
FUZZ_SRC   := $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_BINS  := $(patsubst tests/fuzz/%.c,$(BUILD)/fuzz/%,$(FUZZ_SRC))
FUZZ_FLAGS := $(STD) -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
fuzz_component = $(word 2,$(subst _, ,$(1)))
define fuzz_target
$(BUILD)/fuzz/$(1): tests/fuzz/$(1).c $(foreach c,$(DEPS_$(call fuzz_component,$(1))),$(call libsrcs_of,$(c))) $(LCM_STAMP) $(LCM_COMPAT)
	@mkdir -p $$(dir $$@)
	clang $(FUZZ_FLAGS) -I. -Icommon -Iprotocol -Iprotocol/io -Icompat -I$(GEN) $(PKG_CFLAGS) -w \
	  $$(filter %.c,$$^) $(GEN)/*.c compat/lcm/lcmdec.c -o $$@ $(PKG_LIBS) \
	  $(if $(filter web,$(call fuzz_component,$(1))),-lwebsockets) \
	  $(if $(filter sim,$(call fuzz_component,$(1))),-lchipmunk) -lm
endef
$(foreach t,$(patsubst tests/fuzz/%.c,%,$(FUZZ_SRC)),$(eval $(call fuzz_target,$(t))))
# the body both protocol targets include
$(BUILD)/fuzz/fuzz_protocol_parser $(BUILD)/fuzz/fuzz_protocol_parser2: tests/fuzz/protocol_fuzz.h
$(BUILD)/fuzz/fuzz_daemon_commands $(BUILD)/fuzz/fuzz_web_feed: tests/fuzz/fuzz_records.h
.PHONY: fuzz-build
fuzz-build: $(LCM_STAMP) $(FUZZ_BINS)
fuzz: deps
	@scripts/deps.sh clang
	@$(MAKE) --no-print-directory fuzz-build
	@BUILD=$(BUILD) scripts/fuzz.sh

# lcm-spy needs our types in a jar: javac + lcm.jar (liblcm-java).
LCM_JAR ?= /usr/share/java/lcm.jar
spy-jar: $(BUILD)/undulate-types.jar
$(BUILD)/undulate-types.jar: $(LCM_SRC)
	@scripts/deps.sh default-jdk-headless liblcm-java libjchart2d-java
	@rm -rf $(BUILD)/java && mkdir -p $(BUILD)/java/src $(BUILD)/java/classes
	lcm-gen -j --jpath $(BUILD)/java/src $(LCM_SRC)
	javac -nowarn -cp $(LCM_JAR) -d $(BUILD)/java/classes $$(find $(BUILD)/java/src -name '*.java')
	jar cf $@ -C $(BUILD)/java/classes .

spy: spy-jar
	@scripts/spy.sh $(BUILD)/undulate-types.jar

install: all
	@PREFIX=$(PREFIX) DESTDIR=$(DESTDIR) BUILD=$(BUILD) scripts/install.sh install
uninstall:
	@PREFIX=$(PREFIX) DESTDIR=$(DESTDIR) BUILD=$(BUILD) scripts/install.sh uninstall

clean:
	rm -rf build build-san

-include $(shell find $(OBJ) -name '*.d' 2>/dev/null)
