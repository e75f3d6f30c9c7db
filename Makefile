# povpress build.  `make` builds build/povpress; `make check` runs the unit
# and end-to-end tests (tests/e2e.sh, tests/render.sh); `make demo` renders a
# bundled scene with `povpress render`; `make bench` measures analysis
# throughput and runs the render benchmark in quick mode; `make sweep` is the
# full benchmark: povpress render against POV-Ray's own CPU time and error on
# the bundled scenes (SWEEP_ARGS="--quick scenes/media.pov" passes options to
# scripts/sweep.sh).

CC      ?= cc
CFLAGS  ?= -O3 -g
WARN     = -std=c11 -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes
CPPFLAGS += -D_POSIX_C_SOURCE=200809L -I. $(shell pkg-config --cflags OpenEXR 2>/dev/null)
EXR_LIBS = $(shell pkg-config --libs-only-L OpenEXR 2>/dev/null) -lOpenEXRCore-3_1
LDLIBS  += -lpthread -lm

BUILD = build

REG_SRC = $(wildcard regression/*.c)
DRV_SRC = $(wildcard driver/*.c)
REG_OBJ = $(REG_SRC:%.c=$(BUILD)/%.o)
DRV_OBJ = $(DRV_SRC:%.c=$(BUILD)/%.o)
LIB_DRV_OBJ = $(filter-out $(BUILD)/driver/main.o,$(DRV_OBJ))

UNIT_SRC = $(wildcard tests/test_*.c)
UNIT_BIN = $(UNIT_SRC:tests/%.c=$(BUILD)/tests/%)
TOOL_BIN = $(BUILD)/tests/gen_image $(BUILD)/bench/bench_analyze $(BUILD)/bench/bench_denoise
# povpress and the library it preloads into POV-Ray: what every target that
# renders needs
RENDER_BIN = $(BUILD)/povpress $(BUILD)/povwait.so

.PHONY: all check unit e2e bench clean deps demo sweep sampler
.SECONDARY:
all: $(RENDER_BIN)

# The Debian packages are installed (when missing) once per build tree.
$(BUILD)/.deps: scripts/install-deps.sh
	@mkdir -p $(BUILD)
	scripts/install-deps.sh
	@touch $@

$(BUILD)/%.o: %.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/povpress: $(REG_OBJ) $(DRV_OBJ)
	$(CC) $(CFLAGS) -o $@ $^ $(EXR_LIBS) $(LDLIBS)

# Preloaded into the POV-Ray processes povpress starts: cuts POV-Ray's
# polling waits (driver/povwait/povwait.c).  povpress finds it next to itself.
$(BUILD)/povwait.so: driver/povwait/povwait.c | $(BUILD)/.deps
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -fPIC -shared -o $@ $< -ldl

# tests/render.sh's helper for povwait.so: the waits POV-Ray polls with.
$(BUILD)/tests/povray_waits: tests/povray_waits.c | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -o $@ $< $(LDLIBS)

$(BUILD)/tests/test_%: $(BUILD)/tests/test_%.o $(REG_OBJ) $(LIB_DRV_OBJ)
	$(CC) $(CFLAGS) -o $@ $^ -lcmocka $(EXR_LIBS) $(LDLIBS)

$(BUILD)/tests/gen_image: $(BUILD)/tests/gen_image.o $(LIB_DRV_OBJ) $(REG_OBJ)
	$(CC) $(CFLAGS) -o $@ $^ $(EXR_LIBS) $(LDLIBS)

$(BUILD)/bench/bench_analyze: $(BUILD)/scripts/bench_analyze.o $(REG_OBJ) | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/bench/bench_denoise: $(BUILD)/scripts/bench_denoise.o $(BUILD)/driver/denoise.o \
		$(BUILD)/driver/parallel.o $(BUILD)/driver/errbuf.o | $(BUILD)/.deps
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)

# A helper of the scripts and tests: box-average an EXR (see scripts/boxdown.c).
$(BUILD)/tools/boxdown: $(BUILD)/scripts/boxdown.o $(BUILD)/driver/downsample.o \
		$(BUILD)/driver/image.o $(BUILD)/driver/errbuf.o
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -o $@ $^ $(EXR_LIBS) $(LDLIBS)

deps: $(BUILD)/.deps

unit: $(UNIT_BIN)
	@set -e; for t in $(UNIT_BIN); do echo "== $$t"; $$t; done

e2e: $(RENDER_BIN) $(BUILD)/tests/povray_waits $(BUILD)/tests/gen_image $(BUILD)/tools/boxdown
	tests/e2e.sh $(BUILD)
	tests/render.sh $(BUILD)

check: unit e2e

# Analysis and filter throughput, then povpress render against POV-Ray alone on the
# bundled scenes in quick mode (BENCH_ARGS="scenes/media.pov" for one scene;
# `make sweep` is the full benchmark).
BENCH_ARGS ?=
bench: $(BUILD)/bench/bench_analyze $(BUILD)/bench/bench_denoise $(RENDER_BIN) \
		$(BUILD)/tools/boxdown
	$(BUILD)/bench/bench_analyze
	$(BUILD)/bench/bench_denoise
	BUILD=$(BUILD) scripts/sweep.sh --quick $(BENCH_ARGS)

demo: $(RENDER_BIN) $(BUILD)/tools/boxdown
	scripts/demo.sh $(BUILD)

sweep: $(RENDER_BIN) $(BUILD)/tools/boxdown
	BUILD=$(BUILD) scripts/sweep.sh $(SWEEP_ARGS)

# How a region gets more samples: +AM2 against resolution scaling, measured.
sampler: $(RENDER_BIN) $(BUILD)/tools/boxdown
	scripts/sampler.sh $(BUILD)

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
