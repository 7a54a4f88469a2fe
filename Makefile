# The only two commands a new machine needs: `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.pkm-installed

.PHONY: demo test bench venv clean docs

venv: $(STAMP)

# (Re)create the virtual environment and install pkm (editable) with its test tools and every extra (sweeps,
# figures, homotopy, the benchmarks' baseline MuJoCo: `all`) whenever pyproject.toml changes.
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[dev,all]"
	touch $(STAMP)

demo: $(STAMP)
	$(PY) -m pkm report --out out

# mypy holds one core; meanwhile the tests are collected (a first collection compiles and rewrites every test
# module's assertions, about 10 s of CPU each pytest worker would otherwise pay; bytecode caches written whatever
# PYTHONDONTWRITEBYTECODE says) and MuJoCo Warp's kernels compiled into Warp's cache (tools/warm_caches.py: 30 s of
# CPU the first time on a machine). Their own failures are the test run's to report.
test: $(STAMP)
	$(PY) -m ruff check src tests tools examples
	(env -u PYTHONDONTWRITEBYTECODE $(PY) -m pytest --collect-only -q -p no:cacheprovider >/dev/null 2>&1 || true) & \
		($(PY) tools/warm_caches.py >/dev/null || true) & \
		$(PY) -m mypy src/pkm; status=$$?; wait; exit $$status
	env -u PYTHONDONTWRITEBYTECODE $(PY) -m pytest -q -n 2 --dist worksteal --durations=15  # two workers (CPU-bound, 2 cores), the one done first taking the other's queued tests; the 15 slowest printed: the budget

bench: $(STAMP)
	$(PY) -m pkm bench

clean:
	rm -rf $(VENV) build dist .pytest_cache

# The documentation site, built from the docstrings into site/ (MkDocs, Material, mkdocstrings; warnings are errors):
# installs the `docs` extra into the venv when it is missing. (The two variables silence the banners Material and
# properdocs print about MkDocs 2; they are not build warnings.)
docs: $(STAMP)
	$(PY) -c "import mkdocs, material, mkdocstrings_handlers.python, mkdocs_gen_files, mkdocs_literate_nav, latex2mathml" 2>/dev/null \
		|| $(PY) -m pip install --quiet -e ".[docs]"
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(PY) -m mkdocs build --strict -d site
