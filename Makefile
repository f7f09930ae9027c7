# BGFN artifact -- environment, tests, notebooks -> results/<profile>/, HTML book.
#
#   make reproduce [PROFILE=smoke|quick|paper]   environment + data + notebooks + book (default PROFILE=quick)
#                  [JOBS=n] [DASK_SCHEDULER=tcp://host:8786]   runs at a time here / on a Dask cluster
#   make test                                    pytest (fails when no test ran)
#   make book [PROFILE=...]                      rebuild the book from already executed notebooks
#   make navego-check [PROFILE=...]              NaveGo v1.4 itself under GNU Octave beside our INS rows
#   make bench | make strip | make clean | make distclean | make lock | make help
#
# Make's file dependencies keep a second `make reproduce` cheap: an executed notebook is redone only when its
# source notebook, a profile section it reads, a src/bgfn module it imports, the environment or an executed
# notebook whose outputs it reads changed (tools/notebook_deps.py); the book only when an executed notebook, a
# book source or the code its code pages show changed. Notebooks that read none of each other's outputs run side by
# side (NOTEBOOK_SLOTS).

SHELL := bash
.SHELLFLAGS := -eu -o pipefail -c
.DELETE_ON_ERROR:
.SUFFIXES:
MAKEFLAGS += --no-builtin-rules --no-print-directory
.DEFAULT_GOAL := help

# make splits file names at spaces: a checkout path with one cannot work, so say so before anything is made.
ifneq ($(words $(CURDIR) $(MAKEFILE_LIST)),2)
$(error the path "$(CURDIR)" or "$(MAKEFILE_LIST)" contains a space; make cannot handle it -- move or clone the repository to a path without spaces)
endif

# A profile is a plain name (params/<name>.yaml): letters, digits, '.', '_' or '-', not starting with '.' or '-'.
# It is checked here, by make's own functions, before any shell, recipe or sub-make sees it: its raw text
# ($(value ...): a command-line variable is make code, and expanding it could run a $(shell ...)) with every
# allowed character removed must leave nothing. Anything else (a path, a quote, `;`, `|`, `$`) is refused.
PROFILE ?= quick
NAME_CHARS := a b c d e f g h i j k l m n o p q r s t u v w x y z A B C D E F G H I J K L M N O P Q R S T U V W X Y Z \
              0 1 2 3 4 5 6 7 8 9 _ . -
drop_chars = $(if $(2),$(call drop_chars,$(subst $(firstword $(2)),,$(1)),$(wordlist 2,99,$(2))),$(1))
is_name = $(if $(and $(filter 1,$(words $(1))),$(filter-out -% .%,$(1))),$(if $(call drop_chars,$(1),$(NAME_CHARS)),,ok))
ifeq ($(call is_name,$(value PROFILE)),)
$(error PROFILE "$(value PROFILE)" is not a profile name: expected letters, digits, '.', '_' or '-' (not first: '.' or '-') naming params/<name>.yaml)
endif
# JOBS and DASK_SCHEDULER reach Python (which checks them) as environment values, never as make code.
override JOBS := $(value JOBS)
override DASK_SCHEDULER := $(value DASK_SCHEDULER)
# Every other setting a user may pass is make code as well when it comes from the command line or the environment,
# and a recipe's shell would run what it expands to: its raw text is checked here like PROFILE's, before anything
# expands it. A path (VENV, PYTHON; PY and RES, which tests point elsewhere) is one word of a path's characters;
# options (PIP_FLAGS, PAPERMILL_FLAGS, PYTEST_ARGS) words of an option's (no quote, `$`, `;`, `|`, `&`, `<`, `>`,
# parenthesis, backquote or line break); NOTEBOOK_SLOTS a count; CI a word. A command-line variable that is none of
# these settings is refused (the data step's command, DATA_FETCH, included): nothing else reaches a recipe's shell from
# outside. (What make itself evaluates while it reads its command line, `X!=cmd` or `X:=$(shell cmd)`, it runs before
# any Makefile line: no Makefile can refuse it; the user typed that command.)
comma := ,
space := $(subst ,, )
PATH_CHARS := $(NAME_CHARS) / + ~
OPTION_CHARS := $(PATH_CHARS) = : , @ % [ ]
DIGITS := 0 1 2 3 4 5 6 7 8 9
COUNTS := $(filter-out 0%,$(DIGITS) $(foreach d,$(DIGITS),$(addprefix $(d),$(DIGITS))))
PATH_SETTINGS := VENV PYTHON PY RES
OPTION_SETTINGS := PIP_FLAGS PAPERMILL_FLAGS PYTEST_ARGS
SETTINGS := PROFILE JOBS DASK_SCHEDULER NOTEBOOK_SLOTS CI $(PATH_SETTINGS) $(OPTION_SETTINGS)
from_outside = $(filter command line environment environment override,$(origin $(1)))
is_path = $(and $(filter 1,$(words $(1))),$(filter-out -%,$(1)),$(if $(call drop_chars,$(1),$(PATH_CHARS)),,ok))
is_options = $(if $(subst $(space),,$(call drop_chars,$(1),$(OPTION_CHARS))),,ok)
is_count = $(and $(filter 1,$(words $(1))),$(if $(call drop_chars,$(1),$(DIGITS)),,ok),$(filter $(1),$(COUNTS)))
$(foreach v,$(.VARIABLES),$(if $(filter command line,$(origin $(v))),$(if $(filter $(v),$(SETTINGS)),,$(error \
  $(v) is not a setting of this Makefile (settings: $(SETTINGS)); nothing was run))))
$(foreach v,$(PATH_SETTINGS),$(if $(call from_outside,$(v)),$(if $(call is_path,$(value $(v))),,$(error \
  $(v) "$(value $(v))" is not a path: expected one word of letters, digits and . _ - / + ~ (not first: -)))))
$(foreach v,$(OPTION_SETTINGS),$(if $(call from_outside,$(v)),$(if $(call is_options,$(value $(v))),,$(error \
  $(v) "$(value $(v))" is not a list of options: expected words of letters, digits and . _ - / + ~ = : $(comma) @ % [ ] \
  (no quote, $$, ;, |, &, <, >, parenthesis, backquote or line break)))))
# JOBS and DASK_SCHEDULER: their values are the profile check's to judge (bgfn.profile_schema), their characters
# make's, here (a notebook target made directly runs no profile check first)
$(foreach v,JOBS DASK_SCHEDULER,$(if $(value $(v)),$(if $(call is_options,$(value $(v))),,$(error \
  $(v) "$(value $(v))" is not a value of options' characters: expected letters, digits and . _ - / + ~ = : $(comma) @ % \
  [ ] (no quote, $$, ;, |, &, <, >, parenthesis, backquote or line break)))))
ifneq ($(call from_outside,NOTEBOOK_SLOTS),)
ifeq ($(call is_count,$(value NOTEBOOK_SLOTS)),)
$(error NOTEBOOK_SLOTS "$(value NOTEBOOK_SLOTS)" is not a count: expected a whole number from 1 to 99 (notebooks at a time))
endif
endif
ifneq ($(and $(call from_outside,CI),$(value CI)),)
ifeq ($(call is_name,$(value CI)),)
$(error CI "$(value CI)" is not a word: expected letters, digits, '.', '_' or '-' (CI=true streams the notebooks' output))
endif
endif

# Every path below is relative to the repository root. `make -f <root>/Makefile` from elsewhere re-runs make
# there (`make -C <root>` needs nothing: make changes directory first).
ROOT := $(patsubst %/,%,$(dir $(abspath $(lastword $(MAKEFILE_LIST)))))
ifneq ($(ROOT),$(CURDIR))
$(or $(MAKECMDGOALS),help):
	@$(MAKE) -C "$(ROOT)" -f Makefile $@
.PHONY: $(or $(MAKECMDGOALS),help)
else


VENV ?= .venv
# Interpreter that creates the venv (the project pins Python 3.11).
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
# Extra pip options, e.g. off this machine: PIP_FLAGS="--extra-index-url https://download.pytorch.org/whl/cpu"
PIP_FLAGS ?=
# Data step (module written by bgfn.data): resolve data/raw -> mirror -> pinned URL and verify checksums.
DATA_FETCH = $(PY) -m bgfn.data fetch
# Extra papermill options; in CI (CI=true) cell output is streamed to the log.
PAPERMILL_FLAGS ?= $(if $(filter true 1,$(CI)),--log-output,)
PYTEST_ARGS ?=
# Independent runs (training runs, sweep networks, oracle points) at a time (bgfn.parallel.Runner): empty = the
# profile's `parallel.jobs` (null: the cores here); DASK_SCHEDULER: run them on that Dask cluster instead. Neither
# changes a result, so neither makes a notebook stale.
JOBS ?=
DASK_SCHEDULER ?=
# pip lines that are noise on a mirror-backed machine (kept: errors and real warnings)
PIP_NOISE := is ignored: it is neither a file nor a directory\|^Requirement already satisfied

VENV_ABS := $(abspath $(VENV))
PY := $(VENV_ABS)/bin/python
PIP := $(PY) -m pip
UV := $(VENV_ABS)/bin/uv
UV_PIN := $(shell grep -m1 '^uv==' requirements.lock)
# The stamp names the lock's hash: a changed lock means a new stamp, hence a re-install (pip is idempotent).
LOCK_HASH := $(shell sha256sum requirements.lock | cut -c1-16)
STAMP := $(VENV)/.installed-$(LOCK_HASH)

# The paper's five steps, the studies beyond it, own logs, the results page last.
NOTEBOOKS := 01_data_prep 02_kf_baseline 03_bgfn_training 04_outage_evaluation 05_energy_estimate \
             06_outage_sweep 07_learned_odometer 08_ins_fidelity 09_own_logs 10_results
# A profile's notebooks also depend on the profiles it builds on (`base:` in its YAML), followed to any depth until a
# profile has no base or one already seen; each base name is checked as PROFILE is before it names a file to read.
base_of = $(shell sed -n 's/^base:[[:space:]]*\([^[:space:]#]*\).*/\1/p' 'params/$(1).yaml' 2>/dev/null | tr -d "\"'")
chain_of = $(if $(filter $(1),$(2)),,$(1) $(call bases_of,$(call base_of,$(1)),$(2) $(1)))
bases_of = $(if $(1),$(if $(call is_name,$(1)),$(call chain_of,$(1),$(2)),$(error profile '$(PROFILE)': `base: $(1)` in params/$(lastword $(2)).yaml is not a profile name: expected letters, digits, '.', '_' or '-')))
PARAMS := $(patsubst %,params/%.yaml,$(call chain_of,$(PROFILE)))
RES := results/$(PROFILE)
# A profile whose chain has a `fleet:` section runs notebook 11 (a fleet of drives) after the results page.
FLEET := $(if $(strip $(shell grep -l '^fleet:' $(PARAMS) 2>/dev/null)),11_fleet)
FLEET_EXEC := $(FLEET:%=$(RES)/notebooks/%.ipynb)
EXEC := $(NOTEBOOKS:%=$(RES)/notebooks/%.ipynb) $(FLEET_EXEC)
SRC := $(shell find src/bgfn -name '*.py' -not -path '*/__pycache__/*' | sort)
BOOK_SRC := $(shell find book \( -path book/_build -o -path book/notebooks -o -path book/_generated -o -path book/api \
              -o -name __pycache__ \) -prune -o -type f -print | sort)
BOOK_STAMP := book/_build/.built-$(PROFILE)
KERNELS_COMPILED := $(RES)/logs/.kernels-compiled
BOOK_HTML := book/_build/html/index.html

# Every recipe sees the venv first on PATH and the venv's kernelspec first on JUPYTER_PATH, so papermill's
# `-k python3` runs the venv's ipykernel (kernel.json says "python", which jupyter_client maps to the
# interpreter running papermill, i.e. the venv's).
export PATH := $(VENV_ABS)/bin:$(PATH)
export JUPYTER_PATH := $(VENV_ABS)/share/jupyter
export MPLBACKEND := Agg
export PYDEVD_DISABLE_FILE_VALIDATION := 1
export PYTHONHASHSEED := 0
# Python writes the bytecode of what it imports into .venv (and the gitignored src/**/__pycache__) on first use,
# even where the shell sets PYTHONDONTWRITEBYTECODE: else every notebook kernel and pool worker compiles torch &c.
# again. pip installs without byte-compiling (--no-compile): it compiles every file, most never imported, on one
# core (90 of its 150 s on a 2-core machine).
export PYTHONDONTWRITEBYTECODE :=
export BGFN_JOBS := $(JOBS)
# Results computed once per input and kept for the next notebook that needs them (bgfn.io.cached: each drive's
# GPS-aided run, keyed by the drive's content, the nav: settings and the code): notebooks 03 and 06 take the INS
# attitude from the same run, notebook 08 the runs of notebook 02.
export BGFN_CACHE_DIR := $(CURDIR)/$(RES)/cache
export DASK_SCHEDULER
# the venv's IPython kernel configuration (tools/ipython_kernel_config.py, installed by `make venv`)
KERNEL_CONFIG := $(VENV)/etc/ipython/ipython_kernel_config.py

.PHONY: FORCE help reproduce notebooks _reproduce _notebooks navego-check book _book-build _book-draft test bench clean clean-debris distclean venv data lock strip

ifneq ($(filter reproduce notebooks book,$(MAKECMDGOALS)),)
ifeq ($(wildcard params/$(PROFILE).yaml),)
$(error unknown PROFILE '$(PROFILE)': params/$(PROFILE).yaml does not exist (available: $(basename $(notdir $(wildcard params/*.yaml)))))
endif
# a `base:` that names no profile: say so here, not as make's "No rule to make target"
ifneq ($(filter-out $(wildcard $(PARAMS)),$(PARAMS)),)
$(error profile '$(PROFILE)': its base chain names $(firstword $(filter-out $(wildcard $(PARAMS)),$(PARAMS))), which does not exist -- fix `base:` in $(lastword $(filter $(wildcard $(PARAMS)),$(PARAMS))) (available: $(basename $(notdir $(wildcard params/*.yaml)))))
endif
endif

help:
	@sed -n '3,8p' Makefile | sed 's/^# \{0,1\}//'

# ---------------------------------------------------------------- environment
venv: $(STAMP) $(KERNEL_CONFIG)

$(STAMP): requirements.lock
	@echo "==> environment $(VENV) from requirements.lock ($(LOCK_HASH))"
	@if [ ! -x "$(PY)" ]; then \
	  echo "    creating $(VENV) with $(PYTHON)"; \
	  "$(PYTHON)" -c 'import sys; assert sys.version_info[:2] == (3, 11), "Python 3.11 required, got " + sys.version' ; \
	  "$(PYTHON)" -m venv "$(VENV)"; \
	else echo "    $(VENV) exists: checking it against the lock (already satisfied = nothing to do)"; fi
	@# --no-deps everywhere: the lock is complete; nothing may resolve (spikingjelly declares torchvision/torchaudio,
	@# which would pull CUDA builds of torch). uv (pinned in the lock) installs in parallel: about 20 s on 2 cores
	@# where pip took 60 s. It does not read pip's settings, so pip's index and find-links (environment first, then
	@# pip's configuration) are handed to it, with pip's choice among indexes (the best match over all of them);
	@# where uv cannot be installed or fails, pip installs the same pins.
	@echo "    $(UV_PIN) (pinned in the lock) installs the lock, spikingjelly==2.0.0 and -e . with --no-deps"
	@{ [ -n "$(UV_PIN)" ] && $(PIP) install -q --no-compile $(PIP_FLAGS) --no-deps "$(UV_PIN)" 2>&1 | \
	  { grep -v "$(PIP_NOISE)" || true; }; } || echo "    uv could not be installed (no uv== line in the lock, or pip failed)"
	@pipcfg() { printenv "PIP_$$1" || $(PIP) config get "global.$$2" 2>/dev/null || true; }; \
	for kv in "UV_DEFAULT_INDEX INDEX_URL index-url" "UV_EXTRA_INDEX_URL EXTRA_INDEX_URL extra-index-url" \
	          "UV_FIND_LINKS FIND_LINKS find-links"; do \
	  set -- $$kv; v=$$(pipcfg $$2 $$3); if [ -n "$$v" ]; then export "$$1=$$v"; fi; done; \
	export UV_INDEX_STRATEGY=unsafe-best-match; pkgs="--no-deps $(PIP_FLAGS) -r requirements.lock spikingjelly==2.0.0"; \
	if [ -x "$(UV)" ] && "$(UV)" pip install -q --python "$(PY)" $$pkgs && "$(UV)" pip install -q --python "$(PY)" --no-deps $(PIP_FLAGS) -e .; \
	then :; else echo "    uv is missing or failed: pip installs the same pins (about a minute)"; \
	  $(PIP) install -q --no-compile $$pkgs 2>&1 | { grep -v "$(PIP_NOISE)" || true; }; \
	  $(PIP) install -q $(PIP_FLAGS) --no-deps -e . 2>&1 | { grep -v "$(PIP_NOISE)" || true; }; fi
	@# Every package imports (the first imports of a fresh environment compile its bytecode: seconds on one core).
	@# `make reproduce` on a fresh clone checks the profile's keys beside it (its first imports compile the rest),
	@# their exit status written to the file BGFN_KEYS_STATUS_FILE names.
	@keys=""; if [ -n "$${BGFN_KEYS_STATUS_FILE:-}" ]; then echo "$(CHECK_KEYS_LINE), beside the import check"; \
	  { rc=0; $(PY) -m bgfn.profile_schema --keys $(PROFILE) || rc=$$?; echo $$rc > "$$BGFN_KEYS_STATUS_FILE"; } & \
	  keys=$$!; fi; \
	rc=0; $(PY) -c 'import bgfn, torch, spikingjelly.activation_based, papermill, ipykernel, jupyter_book; \
	  assert torch.version.cuda is None, "a CUDA build of torch is installed: expected the +cpu wheel"; \
	  print("    ok: torch", torch.__version__, "| bgfn from", bgfn.__file__)' || rc=$$?; \
	if [ -n "$$keys" ]; then wait $$keys || true; fi; exit $$rc
	@rm -f $(VENV)/.installed-*
	@touch $@

$(KERNEL_CONFIG): tools/ipython_kernel_config.py | $(STAMP)
	@mkdir -p $(@D) && cp $< $@

# Rewrite requirements.lock from the current venv (keeps the comment header).
lock:
	@{ grep '^#' requirements.lock; $(PIP) freeze --exclude-editable | grep -vi '^spikingjelly==' ; } > requirements.lock.tmp
	@mv requirements.lock.tmp requirements.lock
	@echo "requirements.lock: $$(grep -vc '^#' requirements.lock) packages"

# ---------------------------------------------------------------- data
data: $(STAMP)
	@echo "==> data: $(DATA_FETCH)"
	@$(DATA_FETCH)

# ---------------------------------------------------------------- notebooks
# papermill writes to a temporary name; only a complete run is renamed to the target, so a failed run leaves
# no executed notebook behind (and Make redoes it next time), and the tables, figures and arrays it wrote (the files
# bgfn.io logged for it and, when no other notebook ran beside it, every file of $(RES) newer than its start;
# outside models/, logs/ and cache/) are removed: no half of a notebook's outputs stays beside the other half's
# older copies. Its networks stay: they are checkpoints a rerun resumes from; so do the complete cache entries.
# The notebook's runner (bgfn.parallel) writes one
# line per finished run to $(RES)/logs/<notebook>.log (BGFN_PROGRESS_LOG); `tail` shows them here as they come
# (the first on a line of its own, below papermill's cell bar). Where /usr/bin/time exists, the notebook's wall, user
# and system seconds (papermill, its kernel and the kernel's pool workers) go to $(RES)/logs/<notebook>.cpu, for the
# book's "Reproduce it" page (bgfn.report.walltimes); a pool worker counts once reaped (a Dask cluster's do not)
# and stops after this recipe's shell ($$$$) has ended, having shown the last ones.
# Each notebook also depends on the profile sections it reads and the modules it imports ($(RES)/.deps.mk,
# below), not on the whole profile and every src/bgfn file. Notebooks run side by side (-j, NOTEBOOK_SLOTS): each
# line a notebook prints then starts with its number, and its outputs (bgfn.io logs each file it writes to
# $(RES)/logs/<notebook>.written, BGFN_OUTPUT_LOG) are told apart from its neighbours' when it fails.
# A notebook's OpenMP threads (torch's, numba's) sleep while they wait (OMP_WAIT_POLICY=PASSIVE, unless the
# environment sets it): spinning, they took the cores a notebook beside them needed. Quick's 04 beside 08 took
# 122 CPU s (about 50 alone), 35 with PASSIVE, and 08 finished in 80 s instead of 102 (benchmarks/MEASUREMENTS.md).
# A kernel that dies before it runs a cell is started once more: two kernels started at the same moment can be
# handed the same free port by the system (jupyter_client picks the ports, the kernel binds them a second later;
# seen once in CI as "Address already in use" then "Kernel died before replying to kernel_info").
# Debris of an interrupted run is removed once, before the first notebook (clean-debris, order-only).
$(RES)/notebooks/%.ipynb: notebooks/%.ipynb $(STAMP) | $(KERNELS_COMPILED) data $(KERNEL_CONFIG) clean-debris $(RES)/.profile-checked
	@mkdir -p $(@D) $(RES)/logs
	@echo "==> [$(PROFILE)] papermill $<"
	@tmp="$(@D)/.$*.running-$$$$.ipynb"; log="$(RES)/logs/$*.log"; : > "$$log"; \
	started="$(RES)/logs/.started-$*"; touch "$$started"; written="$(RES)/logs/$*.written"; : > "$$written"; \
	cpu="$(RES)/logs/$*.cpu"; rm -f "$$cpu"; timer=""; \
	if /usr/bin/time -q -f %e -o /dev/null true 2>/dev/null; then timer="/usr/bin/time -q -f %e_%U_%S -o $$cpu"; fi; \
	run() { BGFN_PROGRESS_LOG="$(CURDIR)/$$log" BGFN_OUTPUT_LOG="$(CURDIR)/$$written" \
	  OMP_WAIT_POLICY="$${OMP_WAIT_POLICY:-PASSIVE}" \
	  $$timer $(if $(filter $*,$(LANE)),nice -n $(LANE_NICE) )$(VENV_ABS)/bin/papermill "$<" "$$tmp" -p profile $(PROFILE) --cwd "$(CURDIR)" -k python3 "$$@" $(PAPERMILL_FLAGS); }; \
	if [[ " $(filter -j%,$(MAKEFLAGS)) " =~ [[:space:]]-j([^1]|1[0-9]) ]]; then prefix="[$*] "; else prefix=""; fi; \
	tail --pid=$$$$ -s 0.5 -n +1 -f "$$log" 2>/dev/null | sed -u "s/^/    $$prefix/; 1s/^/\n/" & \
	attempt() { if [ -z "$$prefix" ]; then run --progress-bar; else run --no-progress-bar 2>&1 | sed -u "s/^/$$prefix/"; fi; }; \
	unstarted() { [ -f "$$tmp" ] && $(PY) -c 'import json, sys; sys.exit(any(c.get("execution_count") for c in json.load(open(sys.argv[1]))["cells"]))' "$$tmp"; }; \
	if attempt || { unstarted && echo "    $${prefix}$< ran no cell: its kernel did not start; starting it once more" && \
	                attempt; }; then \
	  mv -f "$$tmp" "$@"; rm -f "$$started"; \
	else rm -f "$$tmp" "$$cpu"; \
	  others=$$(find "$(RES)/logs" -name '.started-*' -not -name ".started-$*" | head -1); \
	  { sort -u "$$written"; if [ -z "$$others" ]; then find "$(CURDIR)/$(RES)" -type f -newer "$$started"; fi; } | \
	    grep -e "^$(CURDIR)/$(RES)/" | grep -v -e "^$(CURDIR)/$(RES)/models/" -e "^$(CURDIR)/$(RES)/logs/" -e "^$(CURDIR)/$(RES)/cache/" \
	      -e '/\.lock$$' | sort -u | while IFS= read -r f; do if [ -f "$$f" ]; then rm -f -- "$$f"; \
	      echo "    removed a partial output of the failed notebook: $${f#$(CURDIR)/}"; fi; done; \
	  rm -f "$$started"; \
	  echo "error: $< failed under PROFILE=$(PROFILE); nothing written to $@, and none of its tables, figures or" \
	       "arrays kept (its networks stay in $(RES)/models/: training resumes; log: $$log)" >&2; \
	  exit 1; fi

# The profile is checked before the first notebook runs: its schema (every notebook's load_profile checks that
# too) and the facts that need the data (outages inside the drives, window, outage sweep). A bad profile fails
# here, naming its file and key, before hours of training.
$(RES)/.profile-checked: $(PARAMS) $(SRC) $(STAMP) | data
	@mkdir -p $(@D) $(RES)/logs
	@echo "==> [$(PROFILE)] check params/$(PROFILE).yaml with its drives"
	@$(PY) -m bgfn.profile_schema $(PROFILE)
	@touch $@

# Beside the data step and the check above, the navigation's numba kernels are compiled into numba's cache, in the
# background (python -m bgfn kernels, bgfn.evaluate.kernels): on a fresh clone notebook 02 would otherwise compile
# them for about 40 s on one core. Started with the data step rather than after the check, they use the core the
# one-core steps leave idle instead of one that notebooks 02 and 07 share. Their output goes to
# $(RES)/logs/kernels.log; they change no result, and what they have not cached yet when a notebook needs it is
# compiled there as before. (A changed src/bgfn file reruns this rule, and numba recompiles the kernels of a
# changed file.) Under reproduce and notebooks they start after the key check (CHECK_KEYS, below: a profile refused
# there leaves no log behind), in the run's process group, without its lock, and end with it (reproduce's recipe,
# whose tools/run_group.py reaps them: their CPU time counts with the run's).
# The stamp is written when they have finished: a run that ends first (a failed data step, a profile the check with
# the drives refuses) starts them again next time.
$(KERNELS_COMPILED): $(PARAMS) $(SRC) $(STAMP)
	@mkdir -p $(@D); rm -f $@
	@echo "==> [$(PROFILE)] numba kernels into the cache, in the background ($(RES)/logs/kernels.log)"
	@{ $(PY) -m bgfn kernels --profile $(PROFILE) && touch $@; } > $(RES)/logs/kernels.log 2>&1 < /dev/null 9>&- &

# Notebook 01 builds the drives' caches: an edited or touched drive reruns it (and so every notebook after it).
$(RES)/notebooks/01_data_prep.ipynb: $(RES)/.data-fingerprint

# What each notebook reads of the profile and which modules it imports: $(RES)/.deps.mk, remade by
# tools/notebook_deps.py on every run of the notebooks (an included makefile: make remakes it first, even under
# -n). The script writes each resolved profile section to $(RES)/.sections/<section>.json, the fingerprint of the
# profile's own CSV drives (every folder it names: their files' sizes and times) to $(RES)/.data-fingerprint and
# that of its fleet's drives to $(RES)/.fleet-fingerprint, each only when it changed: an edited setting reruns the
# notebooks that read it, an edited or touched drive every notebook (through 01), a fleet's drive notebook 11 only,
# and nothing else does.
DEPS_MK := $(RES)/.deps.mk
# a dry run (make -n): its flags' first word holds an n
DRY = $(findstring n,$(filter-out --% %=%,$(firstword $(MAKEFLAGS))))
ifneq ($(filter _reproduce _notebooks $(RES)/%,$(MAKECMDGOALS)),)
include $(DEPS_MK)
endif
# It needs the venv, made first; but make remakes an included makefile even under -n (make -n on a fresh clone
# must not install a venv), so a dry run without a venv writes no rules.
$(DEPS_MK): FORCE $(if $(DRY),,| $(STAMP))
	@mkdir -p $(@D); if [ -x "$(PY)" ]; then $(PY) tools/notebook_deps.py $(PROFILE) --results $(RES); \
	elif [ ! -f $@ ]; then echo "# no venv yet ($(PY)): make venv" > $@; fi
$(RES)/.data-fingerprint $(RES)/.fleet-fingerprint: $(DEPS_MK)
FORCE:

# Notebooks at a time under `make reproduce` / `make notebooks` (1: one after the other, papermill's progress bar
# shown). Each notebook's runner keeps every core (JOBS, else the profile's parallel.jobs, else the cores): the
# chain 01-02-03-06-10 is the longest path, and when the studies beside it are done it must have all of them again; while
# two notebooks run, the system shares the cores between their processes. No table depends on either number.
NOTEBOOK_SLOTS ?= 2

# The notebooks whose outputs a notebook reads. Notebook 01 builds the drives' caches every other one loads.
$(RES)/notebooks/02_kf_baseline.ipynb: $(RES)/notebooks/01_data_prep.ipynb
$(RES)/notebooks/03_bgfn_training.ipynb: $(RES)/notebooks/02_kf_baseline.ipynb
$(RES)/notebooks/04_outage_evaluation.ipynb: $(RES)/notebooks/03_bgfn_training.ipynb
$(RES)/notebooks/05_energy_estimate.ipynb: $(RES)/notebooks/04_outage_evaluation.ipynb
# The studies beyond the paper: 06 builds on notebook 03's networks and learning rates (tables/lr_search.csv) and on
# notebook 04's runs, which it reads from the run cache or computes there itself (bgfn.evaluate.outage_result: the
# two, side by side, compute them once), so it starts beside 04 rather than after it; 07 trains its own odometers,
# 08 reruns the GPS-aided filter and compares our INS with NaveGo's measured run, 09 (the gallery of own logs) needs
# only the data and the navigation: 07, 08 and 09 read no other notebook's outputs, so they run beside notebooks
# 02-06 under -j.
$(RES)/notebooks/06_outage_sweep.ipynb: $(RES)/notebooks/03_bgfn_training.ipynb
$(RES)/notebooks/07_learned_odometer.ipynb: $(RES)/notebooks/01_data_prep.ipynb
$(RES)/notebooks/08_ins_fidelity.ipynb: $(RES)/notebooks/01_data_prep.ipynb $(wildcard data/measured/navego_check.csv)
$(RES)/notebooks/09_own_logs.ipynb: $(RES)/notebooks/01_data_prep.ipynb
# ... yet 08 and 09 start only after 02 (order-only: 02 never makes them rerun). A study ready while both slots are
# busy waits in make's queue and takes the next free slot before anything that became ready later: ready after 01,
# 08 took the slot 02 freed and 03, the head of the longest path (then 03-04-06-10), waited until 08 and 09 were done
# (quick: 03 started at 349 s instead of 91 s). After 02 they are ready with 03, which make starts first (it comes
# first in 10's list); 08 also finds 02's GPS-aided runs in the cache then.
$(RES)/notebooks/08_ins_fidelity.ipynb $(RES)/notebooks/09_own_logs.ipynb: | $(RES)/notebooks/02_kf_baseline.ipynb
# With two slots (the default), one slot is the longest path's (01 02 03 06 10) and the other a lane of the rest,
# one after the other (order-only): 07 beside 02 and 03; 08 beside the rest of 03 (07 ends before 03, and 03's
# serial stretches left a core idle: 16-33 core-s in quick's runs; the order was measured on quick only); 04 once
# 03 and 08 are done; 09 and 05 beside 06, whose serial stretches leave a core free; then the book's draft.
# Chained, a notebook is not queued before its lane's slot is free: queued early, 09 took the slot 03 freed and 04
# waited (23 s). With more slots they run side by side. Only in a whole run (a notebook made alone builds no other
# lane's notebook).
# The lane runs at a lower priority than the longest path (nice; its kernels and pool workers inherit it): where
# both want the cores, the longest path gets them first, and the lane takes what the path's serial stretches leave
# (its work has room to spare beside 02-06). The priority changes no result.
LANE_NICE := 5
ifeq ($(NOTEBOOK_SLOTS),2)
ifneq ($(filter _reproduce _notebooks,$(MAKECMDGOALS)),)
LANE := 07_learned_odometer 08_ins_fidelity 04_outage_evaluation 09_own_logs 05_energy_estimate
$(RES)/notebooks/08_ins_fidelity.ipynb: | $(RES)/notebooks/07_learned_odometer.ipynb
$(RES)/notebooks/04_outage_evaluation.ipynb: | $(RES)/notebooks/08_ins_fidelity.ipynb
$(RES)/notebooks/09_own_logs.ipynb: | $(RES)/notebooks/04_outage_evaluation.ipynb
$(RES)/notebooks/05_energy_estimate.ipynb: | $(RES)/notebooks/09_own_logs.ipynb
endif
endif
$(RES)/notebooks/11_fleet.ipynb: $(RES)/notebooks/01_data_prep.ipynb $(RES)/.fleet-fingerprint
# 10 (the results page) reads every earlier output, the paper's published values and the odometers' run at the
# paper's size recorded from a GPU (python -m bgfn odometers --record).
$(RES)/notebooks/10_results.ipynb: $(filter-out $(RES)/notebooks/10_results.ipynb $(FLEET_EXEC),$(EXEC)) \
  data/paper/outage_max_errors.csv data/paper/claims.yaml $(wildcard data/measured/odometer_sizes.csv)
# ... and, when they have been run, the variant profiles its "Variants" section compares (notebook parameter
# `variants`), so a later `make reproduce PROFILE=quick-heading` is picked up by the next `make reproduce`.
VARIANTS := quick-heading
$(RES)/notebooks/10_results.ipynb: $(wildcard $(filter-out $(RES)/%,$(VARIANTS:%=results/%/notebooks/06_outage_sweep.ipynb)))

_notebooks: $(EXEC)

# ---------------------------------------------------------------- book
# The book shows the executed notebooks of $(PROFILE) (copied to the gitignored book/notebooks/) and the
# profile's tables/figures (copied to book/_generated/, for pages that include them). book/_config.yml has
# execute_notebooks: 'off'. The code page's module pages are written from the docstrings into book/api/ by
# autosummary. Warnings are errors.
# Two passes: the code pages (book/api/, about 150 of the book's 170 pages, their source pages and the theme's
# assets: most of the book's time, much of it on one core) depend on the code alone. Under `make reproduce` a draft
# builds the whole book beside the last notebooks, every other page a placeholder (the source notebooks unexecuted,
# no table or figure; the warnings located in those pages are left out: book/_ext/code_page.py), and the book's build
# then reads every page but the code pages again, with -W, keeping the draft's code pages, their stubs and its
# environment. It keeps them only where book/_build holds this profile's environment ($(BOOK_ENV): every build
# removes every profile's when it starts, and writes its own when it has ended) built from the same files
# ($(BOOK_CODE): the code, the book's sources, the source notebooks, whose titles every page's navigation shows, the
# environment and the build's tool), the same list of them and none changed since the build started; otherwise
# (another profile built the book since, a file changed, was added or removed) it builds every page, as `make book`
# on a fresh clone does.
BOOK_ENV := book/_build/.env-$(PROFILE)
BOOK_ENV_NEXT := book/_build/.next-env-$(PROFILE)
BOOK_DRAFT := $(RES)/logs/.book-draft
BOOK_CODE := $(SRC) $(BOOK_SRC) $(EXEC:$(RES)/notebooks/%=notebooks/%) $(STAMP) tools/build_book.py
same_words = $(if $(filter-out $(1),$(2))$(filter-out $(2),$(1)),,same)
# evaluated when a build's recipe starts, under the book's lock ($(file <...): GNU make 4.2 or newer)
book_pass = $(if $(and $(wildcard $(BOOK_ENV)),$(call same_words,$(file <$(BOOK_ENV)),$(BOOK_CODE)),$(if \
  $(shell find $(BOOK_CODE) -newer $(BOOK_ENV) 2>/dev/null | head -1),,same)),pages,full)
# a build's first step: no profile's environment is kept while book/ changes; the list of files, stamped now
define book_started
	@mkdir -p book/_build && rm -f book/_build/.built-* book/_build/.env-* book/_build/.next-env-*
	@printf '%s\n' $(BOOK_CODE) > $(BOOK_ENV_NEXT)
endef

# $(1): the notebooks shown (the executed ones, or their sources as the draft's placeholders); $(2): the first line of
# _generated/build_info.md
define book_pages
	@rm -rf book/notebooks book/_generated && mkdir -p book/notebooks book/_generated
	@cp $(1) book/notebooks/   # the book's pages: 01-10, and 11 for a profile with a fleet
	@# one parameters cell: the run's values; 11 without a fleet: a page saying the study did not run
	@$(PY) -m bgfn.report.book_notebooks --profile $(PROFILE) --absent book/notebooks book/notebooks/*.ipynb
	@printf '%s\n' "$(2)" "commit \`$$(git rev-parse --short HEAD 2>/dev/null || echo unknown)\`." > book/_generated/build_info.md
endef

# the code pages show module constants' values, some of them paths in this checkout: relative, as the notebooks'
define book_relative_paths
	@{ grep -rlF --include='*.html' '$(CURDIR)' book/_build/html 2>/dev/null || true; } | xargs -r sed -i 's|$(CURDIR)/||g; s|$(CURDIR)|.|g'
endef

# The book's build. It also stamps the draft ($(BOOK_DRAFT), before the book's own stamp): a built book needs no
# draft until the files it is built from change.
define build_book
	@echo "==> book from $(RES)/notebooks$(if $(filter pages,$(book_pass)), (the code pages kept from $(BOOK_ENV)))"
	$(book_started)
	$(if $(filter full,$(book_pass)),@rm -rf book/api)
	$(call book_pages,$(EXEC),Built from the executed notebooks of profile \`$(PROFILE)\` (\`params/$(PROFILE).yaml\`)$(comma))
	@for d in tables figures; do if [ -d "$(RES)/$$d" ]; then cp -r "$(RES)/$$d" book/_generated/; fi; done
	@find book/notebooks book/_generated -name '.*' -type f -delete   # never a temporary or hidden file
	@if [ -f "$(RES)/findings.md" ]; then cp "$(RES)/findings.md" book/_generated/; else \
	  echo "No findings yet: notebook 10 of profile \`$(PROFILE)\` has not written them." > book/_generated/findings.md; fi
	@$(PY) -m bgfn.report.walltimes --profile $(PROFILE) --markdown book/_generated/wall_times.md   # imports pandas, not torch
	@# jupyter-book build book -W -n --keep-going (--all: every page), with Sphinx on every core
	$(if $(filter pages,$(book_pass)),BGFN_BOOK_PASS=pages $(PY) tools/build_book.py book -W -n --keep-going,BGFN_BOOK_PASS= $(PY) tools/build_book.py book --all -W -n --keep-going)
	$(book_relative_paths)
	@mv $(BOOK_ENV_NEXT) $(BOOK_ENV); mkdir -p $(dir $(BOOK_DRAFT)); touch $(BOOK_DRAFT); touch $(BOOK_STAMP)
	@echo "book: $(BOOK_HTML)"
endef

# The draft (the first pass, above): its output goes to $(RES)/logs/book-draft.log. A warning in a code page (or any
# other failure) is shown and leaves no environment: the notebooks go on, and the book's build after them builds every
# page and fails on it, under -W. It reads nothing the notebooks beside it write.
define build_book_draft
	@echo "==> [$(PROFILE)] book draft: the code pages, beside the last notebooks ($(RES)/logs/book-draft.log)"
	$(book_started)
	@rm -rf book/api
	$(call book_pages,$(EXEC:$(RES)/notebooks/%=notebooks/%),Draft of the book of profile \`$(PROFILE)\`: its notebooks have not run yet$(comma))
	@for f in findings wall_times; do echo "Draft: notebook 10 has not run yet." > book/_generated/$$f.md; done
	@if ! BGFN_BOOK_PASS=draft nice -n $(LANE_NICE) $(PY) tools/build_book.py book --all -W -n --keep-going > $(RES)/logs/book-draft.log 2>&1; then \
	  grep -i -e warning -e error $(RES)/logs/book-draft.log >&2 || tail -20 $(RES)/logs/book-draft.log >&2; \
	  echo "    the book's draft failed (log: $(RES)/logs/book-draft.log): the book's build after the notebooks" \
	       "builds every page" >&2; rm -f $(BOOK_ENV_NEXT); exit 0; fi
	$(book_relative_paths)
	@if [ -f $(BOOK_ENV_NEXT) ]; then mv $(BOOK_ENV_NEXT) $(BOOK_ENV); touch $(BOOK_DRAFT); fi
endef

# book/ is one folder for every profile: one build at a time, under an flock (a second one waits, saying so). The
# sub-make is marked as one (+: make hides $(MAKE) inside a variable from itself, and would not share its jobs); a dry
# run (make -n) takes no lock.
BOOK_LOCK := results/.book.lock
locked_book = +@$(if $(DRY),$(MAKE) _book-build,mkdir -p results; exec 7>>$(BOOK_LOCK); if ! flock -n 7; then \
  echo "==> [$(PROFILE)] book/ is being built by another make (another profile's?): waiting for it"; flock 7; fi; \
  $(MAKE) _book-build)

$(BOOK_STAMP): $(EXEC) $(BOOK_CODE)
	$(locked_book)

book: $(STAMP)
	@missing=""; for f in $(EXEC); do [ -f "$$f" ] || missing="$$missing $$f"; done; \
	if [ -n "$$missing" ]; then echo "error: not executed yet:$$missing -- run: make reproduce PROFILE=$(PROFILE)" >&2; exit 1; fi
	$(locked_book)

_book-build:
	$(build_book)

# The draft is part of a whole run with more than one notebook slot, after notebook 05 (the last of the two-slot
# lane beside the longest path, whose 06 and 10 leave a core idle); with one slot it would only add work. It needs
# $(BOOK_CODE), not the notebooks' outputs, and is made again when one of them changes. The book's stamp depends on
# it: a draft made in this run (even one skipped, below) is followed by the book's build. It is made when book/_build
# holds no environment of this profile, too. Skipped, saying so, where no notebook runs beside it (a book page edited
# and nothing else: one build of every page is quicker) and while another make builds the book (the book's build
# then builds every page).
$(BOOK_DRAFT): $(BOOK_CODE) $(if $(wildcard $(BOOK_ENV)),,FORCE)
	@$(if $(DRY),$(MAKE) _book-draft,if [ -z "$$(find $(RES)/logs -name '.started-*' 2>/dev/null | head -1)" ]; then \
	  echo "==> [$(PROFILE)] book draft skipped: no notebook runs beside it (the book's build builds every page)"; exit 0; fi; \
	mkdir -p $(@D) results; exec 7>>$(BOOK_LOCK); if ! flock -n 7; then \
	  echo "==> [$(PROFILE)] book draft skipped: book/ is being built by another make"; exit 0; fi; \
	  $(MAKE) _book-draft)

_book-draft:
	$(build_book_draft)

ifneq ($(NOTEBOOK_SLOTS),1)
ifneq ($(filter _reproduce,$(MAKECMDGOALS)),)
$(BOOK_STAMP): $(BOOK_DRAFT)
$(BOOK_DRAFT): | $(RES)/notebooks/05_energy_estimate.ipynb
endif
endif

# One run per profile at a time: `reproduce` and `notebooks` hold an flock on $(RES)/.lock (which names the
# holder's PID) for the whole run, so a second run of the same profile refuses at once instead of overwriting
# the first one's results or cleaning its live files as debris; other profiles run beside it. The profile's keys
# (and JOBS, DASK_SCHEDULER) are checked first, before the lock, the install's updates and the data (with no
# venv yet: once the packages are installed, beside the check that they import). The lock is an open file
# descriptor, held by the run's processes only: a run that ends for any reason releases it, and no dead PID ever
# blocks (a PID left in the file by a killed run is taken over, said once). The run is a process group of its own
# (tools/run_group.py: setsid, and a subreaper that reaps every process of the run, so a background job's CPU time
# is counted with the run's by /usr/bin/time): SIGINT, SIGTERM or SIGHUP of this make, or its end, sends SIGTERM to
# every process of it (a background job ignores SIGINT), background jobs included (a notebook's kernel ends with
# papermill, and its pool workers with the kernel: bgfn.parallel.watch_owner).
LOCK := $(RES)/.lock
CHECK_KEYS_LINE = ==> [$(PROFILE)] check params/$(PROFILE).yaml (every key; JOBS, DASK_SCHEDULER)
CHECK_KEYS = echo "$(CHECK_KEYS_LINE)" && $(if $(DRY),echo )$(PY) -m bgfn.profile_schema --keys $(PROFILE)
reproduce notebooks:
	@if [ -x "$(PY)" ]; then $(CHECK_KEYS); fi
	@mkdir -p $(RES); exec 9>>"$(LOCK)"; \
	if ! flock -n 9; then pid=$$(cat "$(LOCK)" 2>/dev/null); \
	  echo "error: make $@ PROFILE=$(PROFILE) is already running (PID $${pid:-unknown}$$(kill -0 "$${pid:-0}" \
	       2>/dev/null || echo ", ended; a process it started still holds the lock"), lock $(LOCK)); wait for it" \
	       "to end or stop it -- two runs of one profile would overwrite each other's results" >&2; \
	  exit 1; fi; \
	old=$$(cat "$(LOCK)"); if [ -n "$$old" ]; then echo "    $(LOCK) named PID $$old, a run that was killed" \
	  "before it could clear it; the lock was free: taken over"; fi; \
	echo $$$$ > "$(LOCK)"; export BGFN_RUN_LOCK=$$$$; run=0; \
	stop='[ $$run = 0 ] || kill -TERM -- -$$run 2>/dev/null || kill -TERM $$run 2>/dev/null || true'; \
	trap "$$stop" INT TERM HUP; \
	trap "$$stop"'; : > "$(LOCK)"; exec 9>&- 8>>"$(LOCK)"; \
	  flock -w 10 8 || true' EXIT; \
	if [ ! -x "$(PY)" ]; then status=$$(mktemp); BGFN_KEYS_STATUS_FILE=$$status $(MAKE) venv || { rm -f $$status; exit 1; }; \
	  keys=$$(cat $$status); rm -f $$status; \
	  if [ -z "$$keys" ]; then $(CHECK_KEYS); elif [ "$$keys" != 0 ]; then exit $$keys; fi; fi; \
	$(PY) tools/run_group.py $(MAKE) -j$(NOTEBOOK_SLOTS) _$@ & run=$$!; \
	rc=0; wait $$run || rc=$$?; while kill -0 $$run 2>/dev/null; do wait $$run || rc=$$?; done; run=0; exit $$rc

_reproduce: $(BOOK_STAMP)
	@echo "==> done (PROFILE=$(PROFILE)): results in $(RES)/, book at $(BOOK_HTML)"

# ---------------------------------------------------------------- tests, benchmarks
test: $(STAMP)
	@mkdir -p results
	$(PY) -m pytest $(PYTEST_ARGS) --junitxml=results/pytest-junit.xml
	@$(PY) -c 'import sys, xml.etree.ElementTree as ET; r = ET.parse("results/pytest-junit.xml").getroot(); \
	  s = r if r.tag == "testsuite" else r.find("testsuite"); n = int(s.get("tests", 0)) - int(s.get("skipped", 0)); \
	  sys.exit(0) if n > 0 else sys.exit("error: no test ran (all skipped or none collected)")'

bench: $(STAMP)
	@shopt -s nullglob; files=(benchmarks/bench_*.py); \
	if [ $${#files[@]} -eq 0 ]; then echo "no benchmarks/bench_*.py yet"; exit 0; fi; \
	for f in "$${files[@]}"; do echo "==> $$f"; $(PY) "$$f"; done; \
	echo "==> results/bench.json"

# Store notebooks without outputs: clear outputs/execution counts of notebooks/*.ipynb (rewrites only the
# notebooks that carry some).
strip: $(STAMP)
	@$(PY) -c 'import sys, glob, nbformat; \
	  paths = sorted(glob.glob("notebooks/*.ipynb")); \
	  dirty = [p for p in paths if any(c.get("outputs") or c.get("execution_count") for c in nbformat.read(p, 4).cells if c.cell_type == "code")]; \
	  [nbformat.write((lambda nb: ([c.update(outputs=[], execution_count=None) for c in nb.cells if c.cell_type == "code"], nb)[1])(nbformat.read(p, 4)), p) for p in dirty]; \
	  print("stripped:", " ".join(dirty) if dirty else "nothing (all notebooks clean)")'

# ---------------------------------------------------------------- NaveGo beside us
# NaveGo v1.4's own ins_gnss.m under GNU Octave on the Turin drives and the profile's outages
# (tools/navego_check.py, NaveGo read from ../shared/navego-v1.4): its numbers go to data/measured/navego_check.csv,
# which the book shows beside our `navego` setup. Not part of `reproduce`: the artifact never needs Octave.
navego-check: $(STAMP)
	@command -v octave >/dev/null || { echo "error: GNU Octave is not installed -- apt-get install -y octave" \
	  "octave-control (Debian/Ubuntu), then make navego-check" >&2; exit 1; }
	$(PY) tools/navego_check.py --profile $(PROFILE)

# ---------------------------------------------------------------- cleaning
# Debris of an interrupted run of $(PROFILE): papermill's temporary notebooks and half-written outputs
# (bgfn.io.atomic_path names them .<name>.<random>.tmp<suffix>). Inside the run that holds the profile's lock
# (reproduce, notebooks: BGFN_RUN_LOCK names it) notebooks run one at a time, so none of them is live; from
# anywhere else it takes the lock first, and removes nothing while a run holds it.
clean-debris:
	@if [ -d "$(RES)" ]; then \
	  if [ -z "$${BGFN_RUN_LOCK:-}" ] || [ "$$BGFN_RUN_LOCK" != "$$(cat "$(LOCK)" 2>/dev/null)" ]; then \
	    exec 8>>"$(LOCK)"; if ! flock -n 8; then \
	    echo "clean-debris: a run of $(PROFILE) is live (PID $$(cat "$(LOCK)"), lock $(LOCK)): nothing removed" >&2; \
	    exit 1; fi; fi; \
	  find "$(RES)" -type f \( -name '.*.running-*.ipynb' -o -name '.*.tmp*' \) \
	  -print -delete | sed 's/^/    removed debris of an interrupted run: /'; fi

clean:
	rm -rf results book/_build book/notebooks book/_generated book/api

distclean: clean
	rm -rf $(VENV) data/processed

endif  # ROOT == CURDIR
