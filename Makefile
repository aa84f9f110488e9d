# gearwear: two commands on a fresh machine.
#   make demo   set up .venv and run the main job on the built-in paper gear pair
#   make test   set up .venv and run the test suite
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
OUT    ?= out/demo

.PHONY: demo test bench venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(VENV)/bin/gearwear geometry --wear severe --clearance-um 10 --out $(OUT)

test: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(PY) -m pytest -q

bench: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(PY) benchmarks/run_all.py

clean:
	rm -rf $(VENV) out .pytest_cache .hypothesis
