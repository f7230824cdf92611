# mpmlab: install, build, test and reproduce every result.
#
#   make            (= make all) install what is missing, build, run every experiments/*.yaml
#                   into results/<name>/, write its report, and the reproduction index
#                   results/README.md
#   make test       lint, unit tests, reduced matrices in tests/matrices/, `mpmlab report
#                   --check` on each reduced matrix, HDF5 layout and XDMF tests, test-slurm,
#                   then reproduce
#   make test-slurm the reduced matrices as a Slurm array on a one-node cluster started for
#                   the test (installs slurm and munge when missing), compared bit for bit
#                   with a single-machine run
#   make reproduce  every experiment from scratch into target/reproduce, compared byte for
#                   byte with the committed results/ (part of make test)
#   make bench      per method: particle-steps per second, cost relative to mpm beside its
#                   target, peak heap per particle
#   make fuzz       mutation fuzzing of the experiment front end and of `run` on tiny
#                   problems for FUZZ_SECONDS (default 300); findings in target/fuzz/findings/
#   make deps       only install what is missing (libhdf5-dev, pkg-config, .venv)
#   make clean-results   delete generated HDF5 run files and their XDMF descriptions
#                   (reports and figures stay)
#
# Variables: JOBS=N (parallel runs, default: all cores), FORCE=1 (re-run complete runs),
# RESULTS=DIR (output of `make all`, default results), PYTHON=python3 (to create .venv),
# FUZZ_SECONDS=S and FUZZ_SEED=N (make fuzz; the seed defaults to the clock).
#
# Convention: an experiment file's stem equals its `name:` (experiments/foo.yaml has
# `name: foo`), because its results go to results/<name>/. The recipes check this.

SHELL := bash
.SHELLFLAGS := -eu -o pipefail -c
.ONESHELL:
.DELETE_ON_ERROR:
.DEFAULT_GOAL := all
MAKEFLAGS += --no-builtin-rules

# rustup puts cargo in ~/.cargo/bin, which a non-login shell may not have on PATH.
CARGO_BIN_DIR := $(or $(CARGO_HOME),$(HOME)/.cargo)/bin
ifneq ($(wildcard $(CARGO_BIN_DIR)/cargo),)
export PATH := $(CARGO_BIN_DIR):$(PATH)
endif

CARGO ?= cargo
PYTHON ?= python3
RESULTS ?= results
JOBS ?=
FORCE ?=
FUZZ_SECONDS ?= 300
FUZZ_SEED ?=

# cargo builds into $CARGO_TARGET_DIR when it is set.
BIN := $(or $(CARGO_TARGET_DIR),target)/release/mpmlab
VENV := .venv
VENV_PY := $(VENV)/bin/python
PY_REQUIREMENTS := tests/python/requirements.txt
VENV_STAMP := $(VENV)/.mpmlab-requirements
TEST_OUT := target/test-matrices
REPRO_OUT := target/reproduce

EXPERIMENTS = $(sort $(wildcard experiments/*.yaml))
MATRICES = $(sort $(wildcard tests/matrices/*.yaml))
RUN_FLAGS = $(if $(JOBS),--jobs $(JOBS)) $(if $(FORCE),--force)

# die, step, apt_install, check_stems
SH_LIB := source scripts/lib.sh

.PHONY: all deps deps-system deps-python build lint test test-slurm reproduce bench fuzz clean-results

all: deps build
	@$(SH_LIB)
	files=($(EXPERIMENTS))
	[ $${#files[@]} -gt 0 ] || die "no experiments/*.yaml to run"
	check_stems "$${files[@]}"
	step "$(BIN) run --out $(RESULTS) $(RUN_FLAGS) $${files[*]}"
	$(BIN) run --out "$(RESULTS)" $(RUN_FLAGS) "$${files[@]}"
	for f in "$${files[@]}"; do
	  name=$$(basename "$$f" .yaml)
	  step "$(BIN) report $(RESULTS)/$$name"
	  $(BIN) report "$(RESULTS)/$$name"
	done
	step "$(BIN) index $(RESULTS)"
	$(BIN) index "$(RESULTS)"
	echo "reports: $(RESULTS)/*/report.md, index: $(RESULTS)/README.md"

deps: deps-system deps-python

# libhdf5-dev through pkg-config is how the hdf5-metno crate finds HDF5 (on Debian the
# serial library under /usr/lib/<arch>/hdf5/serial; no HDF5_DIR needed).
deps-system:
	@$(SH_LIB)
	command -v $(CARGO) >/dev/null 2>&1 || die "cargo not found (looked on PATH and in $(CARGO_BIN_DIR)); install a Rust toolchain with rustup"
	pkgs=()
	if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists hdf5; then
	  pkgs+=(libhdf5-dev pkg-config)
	fi
	command -v cc >/dev/null 2>&1 || pkgs+=(gcc)
	if [ $${#pkgs[@]} -gt 0 ]; then
	  apt_install "$${pkgs[@]}"
	  pkg-config --exists hdf5 || die "pkg-config still does not find hdf5 after installing libhdf5-dev"
	fi

deps-python: $(VENV_STAMP)

# Re-installed only when the requirements change or the venv is missing.
$(VENV_STAMP): $(PY_REQUIREMENTS)
	@$(SH_LIB)
	if ! "$(VENV_PY)" -m pip --version >/dev/null 2>&1; then
	  step "$(PYTHON) -m venv $(VENV)"
	  if ! $(PYTHON) -m venv --clear $(VENV); then
	    apt_install python3-venv
	    $(PYTHON) -m venv --clear $(VENV)
	  fi
	fi
	step "pip install -r $(PY_REQUIREMENTS)"
	"$(VENV_PY)" -m pip install --quiet --disable-pip-version-check -r $(PY_REQUIREMENTS)
	touch $@

build: deps-system
	@$(SH_LIB)
	step "$(CARGO) build --release"
	$(CARGO) build --release

lint: deps-system
	@$(SH_LIB)
	step "$(CARGO) fmt --check"
	$(CARGO) fmt --check
	step "$(CARGO) clippy --all-targets --release -- -D warnings"
	$(CARGO) clippy --all-targets --release -- -D warnings

# The reduced matrices run into a fresh $(TEST_OUT); their files are then checked by the
# Python layout test and their fitted rates by `mpmlab report --check`.
test: deps lint build
	@$(SH_LIB)
	step "$(CARGO) test --release"
	$(CARGO) test --release
	files=($(MATRICES))
	[ $${#files[@]} -gt 0 ] || die "no tests/matrices/*.yaml: the reduced matrices are part of the test suite"
	check_stems "$${files[@]}"
	rm -rf "$(TEST_OUT)"
	mkdir -p "$(TEST_OUT)"
	step "$(BIN) run --out $(TEST_OUT) $(RUN_FLAGS) $${files[*]}"
	$(BIN) run --out "$(TEST_OUT)" $(RUN_FLAGS) "$${files[@]}"
	for f in "$${files[@]}"; do
	  name=$$(basename "$$f" .yaml)
	  step "$(BIN) report $(TEST_OUT)/$$name --check"
	  $(BIN) report "$(TEST_OUT)/$$name" --check
	done
	# After the reports, so that the layout test also checks the figures' data files.
	step "pytest tests/python (MPMLAB_RESULTS=$(TEST_OUT))"
	MPMLAB_RESULTS="$(abspath $(TEST_OUT))" MPMLAB_BIN="$(abspath $(BIN))" "$(VENV_PY)" -m pytest tests/python -q -p no:cacheprovider
	step "scripts/test-slurm.sh (make test-slurm)"
	scripts/test-slurm.sh "$(BIN)" "$(VENV_PY)"
	$(MAKE) --no-print-directory reproduce

# Every experiment from scratch into $(REPRO_OUT), compared byte for byte with the committed
# results/ (all but the run files and the wall times, timings.csv and costs.md, which are
# not committed).
reproduce: deps build
	@$(SH_LIB)
	rm -rf "$(REPRO_OUT)"
	$(MAKE) --no-print-directory all RESULTS="$(REPRO_OUT)" FORCE=
	step "diff -r results $(REPRO_OUT)"
	diff -r -q -x runs -x timings.csv -x costs.md results "$(REPRO_OUT)" \
	  || die "the committed results/ differ from a fresh make all (listed above)"
	echo "committed results reproduce byte for byte"

# A one-node Slurm cluster in a temporary directory, stopped again by the script; see the
# comment at the top of scripts/test-slurm.sh.
test-slurm: deps build
	@$(SH_LIB)
	step "scripts/test-slurm.sh"
	scripts/test-slurm.sh "$(BIN)" "$(VENV_PY)"

bench: deps-system
	@$(SH_LIB)
	step "$(CARGO) bench --bench throughput"
	$(CARGO) bench --bench throughput

# Open-ended: `make test` replays a fixed set of mutants and the kept findings instead
# (tests/front_end_fuzz.rs).
fuzz: deps-system
	@$(SH_LIB)
	step "cargo test --test front_end_fuzz fuzz_open_ended ($(FUZZ_SECONDS) s)"
	MPMLAB_FUZZ_SECONDS=$(FUZZ_SECONDS) $(if $(FUZZ_SEED),MPMLAB_FUZZ_SEED=$(FUZZ_SEED)) \
	  $(CARGO) test --release --test front_end_fuzz fuzz_open_ended -- --ignored --nocapture

clean-results:
	@$(SH_LIB)
	if [ -d "$(RESULTS)" ]; then
	  find "$(RESULTS)" -type f \( -name '*.h5' -o -name '*.h5.tmp*' -o -name '*.xdmf' \
	    -o -name '*.xdmf.tmp*' \) -print -delete
	fi
