# gearwear: two commands on a fresh machine.
#   make demo   set up .venv and run the main job on the built-in paper gear pair
#   make test   set up .venv and run the test suite
#   make check  the fast tier: lint and format (ruff), types (mypy on the built wheel), the tests not marked slow
#   make docs   the API reference from the docstrings into build/api/ (pdoc, the docs extra)
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed-stamp
DOCS_STAMP := $(VENV)/.docs-stamp
OUT    ?= out/demo

BENCH_VENV  := .venv-bench
BENCH_STAMP := $(BENCH_VENV)/.installed-stamp

.PHONY: demo test check docs bench report venv clean fe-design-space atlas

venv: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(VENV)/bin/gearwear geometry --wear severe --clearance-um 10 --out $(OUT)/geometry
	$(VENV)/bin/gearwear stiffness --wear unworn mild severe --out $(OUT)/stiffness
	$(VENV)/bin/gearwear simulate --out $(OUT)/simulate

test: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(PY) -m pytest -q -n 2

check: $(STAMP)
	$(PY) -m ruff check .
	$(PY) -m ruff format --check .
	$(PY) tools/check_types.py
	$(PY) -m pytest -q -n 2 -m "not slow and not design_space"

# The API reference: one page per module of gearwear and its layers, into build/api/ (git-ignored).
# Fails on a module that does not import, a pdoc warning or a broken cross-reference (tools/api_docs.py).
# The docs extra goes into the same .venv, once (its own stamp: make test and make check do not install it).
$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(PY) -m pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	$(PY) tools/api_docs.py --out build/api

# The pair FE on 200 Sobol designs of the geometry's whole space (an hour or more; not in make test)
fe-design-space: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(PY) -m pytest -q -n 2 -m design_space tests/test_fe_design_space.py

# The stiffness atlas of issue 28 (atlas.toml: 500 designs; resumable, each design cached in
# $(GEARWEAR_CACHE) or ~/.cache/gearwear/tables/atlas; hours on 2 cores; not in make test)
ATLAS_SCHEDULER ?= local:2
atlas: $(STAMP)
	@$(PY) -m gearwear.envcheck
	$(VENV)/bin/gearwear atlas atlas.toml --scheduler $(ATLAS_SCHEDULER) --out reports/atlas
	$(PY) -m gearwear.reports.atlas reports/atlas

# ROSS (the peer for the stiffness benchmark) lives in its own venv: it is not a
# runtime dependency. Its install is best-effort; the benchmark notes a missing peer.
$(BENCH_STAMP):
	$(PYTHON) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(BENCH_VENV)/bin/python -m pip install --quiet 'ross-rotordynamics==2.3.0' 'plotly<7'
	touch $(BENCH_STAMP)

bench: $(STAMP)
	-@$(MAKE) --no-print-directory $(BENCH_STAMP)
	@$(PY) -m gearwear.envcheck
	$(PY) benchmarks/run_all.py

# Regenerate the committed reports/ (see reports/README.md); a few minutes.
report: $(STAMP)
	@$(PY) -m gearwear.envcheck
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear report paper --out reports/paper
	$(VENV)/bin/gearwear report pair examples/shifted_pair.toml --out reports/pair/shifted_pair
	$(VENV)/bin/gearwear verify --out reports/verification
	$(VENV)/bin/gearwear stiffness --wear unworn mild severe --out reports/stiffness_wear
	$(VENV)/bin/gearwear stiffness --clearance-um 0 25 50 75 100 --out reports/stiffness_clearance
	$(VENV)/bin/gearwear stiffness --method fem --wear unworn mild severe --out reports/stiffness_fem
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear calibrate --wear unworn mild severe --out reports/calibrated
	$(VENV)/bin/gearwear runup examples/runup_backlash.toml --set operating.speed_rpm=1000:3000:41 --out reports/runup/backlash_50rpm
	$(VENV)/bin/gearwear runup examples/runup_backlash.toml --set operating.speed_rpm=1000:3000:81 --out reports/runup/backlash_25rpm
	$(VENV)/bin/gearwear runup paper-default --set operating.speed_rpm=1000:12000:111 --out reports/runup/paper_default
	$(VENV)/bin/gearwear sweep paper-clearance --set effects.bearing_clearance.clearance_um=20:40:41 --out reports/breakpoints/clearance_sweep
	$(PY) benchmarks/clearance_sweep_report.py
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear diagnose examples/diagnose/scene.toml --measured examples/diagnose/measured_timeseries.csv --out reports/diagnose/timeseries
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear diagnose examples/diagnose/scene.toml --measured examples/diagnose/measured_harmonics.csv --out reports/diagnose/harmonics
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear diagnose examples/diagnose/scene.toml --measured examples/diagnose/measured_timeseries.csv --unknowns wear,clearance,torque --out reports/diagnose/torque
	GEARWEAR_CACHE=$(CURDIR)/.gearwear-cache $(VENV)/bin/gearwear diagnose --plan examples/diagnose/scene.toml --out reports/diagnose/plan
	for s in tip_relief measured_deviation root_crack spall; do \
	  $(VENV)/bin/gearwear stiffness examples/$$s.toml --out reports/examples/$$s/stiffness || exit 1; \
	  $(VENV)/bin/gearwear simulate examples/$$s.toml --out reports/examples/$$s/simulate || exit 1; \
	done
	for s in root_crack spall; do \
	  $(VENV)/bin/gearwear stiffness examples/$$s.toml --method fem --out reports/examples/$$s/stiffness_fem || exit 1; \
	  $(VENV)/bin/gearwear simulate examples/$$s.toml --set effects.mesh_stiffness.source=fem \
	    --out reports/examples/$$s/simulate_fem || exit 1; \
	done

clean:
	rm -rf $(VENV) $(BENCH_VENV) out .pytest_cache .hypothesis build/api
