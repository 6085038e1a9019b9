# Set-up, demo and tests. `make demo` and `make test` are the two commands in
# the README; both create the project venv first (once; a stamp file records
# that requirements-dev.txt has been installed). `make docs` and `make lint`
# add their own tools to the same venv, each with its own stamp.

# bpy 5.0.1 is built for Python 3.11: prefer python3.11, else python3.
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3)
VENV := .venv
VENV_PYTHON := $(VENV)/bin/python
VENV_STAMP := $(VENV)/.solidwire-requirements-installed
DEMO_IMAGE := out/demo.png
DIST_DIR := dist

# Blender's own extension validator/builder, shipped inside the bpy wheel.
BLENDER_EXT = $(VENV_PYTHON) -c "import importlib.util, os; \
	print(os.path.join(importlib.util.find_spec('bpy').submodule_search_locations[0], \
	'5.0', 'scripts', 'addons_core', 'bl_pkg', 'cli', 'blender_ext.py'))"
BLENDER_TAGS = $(VENV_PYTHON) -c "import importlib.util, os; \
	print(os.path.join(importlib.util.find_spec('bpy').submodule_search_locations[0], \
	'5.0', 'scripts', 'modules', '_bpy_internal', 'extensions', 'tags.py'))"

.PHONY: demo test docs lint test-newest venv venv-newest zip check-system clean bench bench-scale bench-engines bench-viewport bench-regions fetch-meshes test-slow soak fuzz compat galleries

venv: $(VENV_STAMP)

$(VENV_STAMP): requirements-dev.txt
	@test -n "$(PYTHON)" || { echo "error: no python3.11 or python3 on PATH" >&2; exit 1; }
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' || \
		{ echo "error: $(PYTHON) is not Python 3.11, which bpy==5.0.1 needs (set PYTHON=/path/to/python3.11)" >&2; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(VENV_PYTHON) -m pip install --disable-pip-version-check -r requirements-dev.txt
	touch $(VENV_STAMP)

# The manual's and the linter's tools, on top of the project venv.
DOCS_STAMP := $(VENV)/.solidwire-docs-installed
LINT_STAMP := $(VENV)/.solidwire-lint-installed

$(DOCS_STAMP): requirements-docs.txt $(VENV_STAMP)
	$(VENV_PYTHON) -m pip install --disable-pip-version-check -r requirements-docs.txt
	touch $(DOCS_STAMP)

$(LINT_STAMP): requirements-lint.txt $(VENV_STAMP)
	$(VENV_PYTHON) -m pip install --disable-pip-version-check -r requirements-lint.txt
	touch $(LINT_STAMP)

# The manual (mkdocs.yml: docs/ -> build/site/), strict: a broken link or
# anchor fails the build.
docs: $(DOCS_STAMP)
	$(VENV_PYTHON) -m mkdocs build --strict --site-dir build/site

# The linter and the formatter (configured in pyproject.toml), both checked.
lint: $(LINT_STAMP)
	$(VENV_PYTHON) -m ruff check .
	$(VENV_PYTHON) -m ruff format --check .

# bpy renders through EGL (Mesa's llvmpipe without a GPU); warn early instead
# of failing later with an obscure import error.
check-system:
	@if command -v ldconfig >/dev/null 2>&1 && ! ldconfig -p | grep -q 'libEGL.so.1'; then \
		echo "warning: libEGL.so.1 not found; on Debian/Ubuntu: sudo apt-get install libegl1 libgl1-mesa-dri" >&2; \
	fi

demo: $(VENV_STAMP) check-system
	$(VENV_PYTHON) scripts/render.py --demo -o $(DEMO_IMAGE)

# -X faulthandler: a crash inside the GPU driver names the test and the line.
test: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -X faulthandler -m pytest tests

# The newest Blender on the package index (bpy 5.3.0, Python 3.13) in its own
# venv: CI runs the whole suite on it too. Python 3.13 from PATH, or pyenv's.
NEWEST_VENV := .venv-newest
NEWEST_STAMP := $(NEWEST_VENV)/.solidwire-requirements-installed
$(NEWEST_STAMP): requirements-newest.txt
	@py=$$(command -v python3.13 2>/dev/null); \
	{ [ -n "$$py" ] && $$py -c 'import sys' 2>/dev/null; } || py=$$(ls -d $$(pyenv root 2>/dev/null)/versions/3.13*/bin/python3.13 2>/dev/null | tail -n 1); \
	test -n "$$py" || { echo "error: Python 3.13 not found (bpy 5.3 needs it)" >&2; exit 1; }; \
	$$py -m venv $(NEWEST_VENV)
	$(NEWEST_VENV)/bin/python -m pip install --disable-pip-version-check -r requirements-newest.txt
	touch $(NEWEST_STAMP)

venv-newest: $(NEWEST_STAMP)

test-newest: $(NEWEST_STAMP) check-system
	$(NEWEST_VENV)/bin/python -X faulthandler -m pytest tests

# The installable extension zip, validated and built by Blender's own tool.
zip: $(VENV_STAMP)
	$(VENV_PYTHON) "$$($(BLENDER_EXT))" validate --valid-tags "$$($(BLENDER_TAGS))" .
	mkdir -p $(DIST_DIR)
	$(VENV_PYTHON) "$$($(BLENDER_EXT))" build --valid-tags "$$($(BLENDER_TAGS))" --source-dir . --output-dir $(DIST_DIR)

# Benchmarks (numbers in docs/dev/benchmarks.md; matplotlib is a benchmark-only dependency).
fetch-meshes: $(VENV_STAMP)
	$(VENV_PYTHON) scripts/fetch_meshes.py

bench: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m pip install --disable-pip-version-check -q -r requirements-bench.txt
	$(VENV_PYTHON) -m scripts.bench $(BENCH_ARGS)

bench-scale: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m scripts.bench_scale $(BENCH_ARGS)

# F12 against Workbench (and Freestyle), with SolidWire's frame stage by stage.
bench-engines: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m scripts.bench_engines --size 1280x720 --size 3840x2160 --repeats 5 --freestyle $(BENCH_ARGS)

# Blender's real viewport drawn headless: its own redraws, with its wireframe
# overlay, with SolidWire's overlay (docs/dev/viewport-benchmark.md; a few
# minutes; BENCH_ARGS=--quick for 62k triangles only).
bench-viewport: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m scripts.bench_viewport --profile --output docs/dev/viewport-benchmark.md $(BENCH_ARGS)

# What regions cost: the cage look against every edge, the angle threshold
# and edge classes against a plain frame (docs/dev/benchmarks.md).
bench-regions: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m scripts.bench_regions $(BENCH_ARGS)

# The manual's pictures (docs/*.png), labelled (Pillow, from
# requirements-bench.txt). The wire-over pictures render Cycles and need the
# fetched meshes: `python -m scripts.wire_over_gallery` on its own.
GALLERIES := preset_gallery line_styles_gallery look_gallery edges_gallery outlines_gallery object_types_gallery hair_points_gallery
galleries: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m pip install --disable-pip-version-check -q -r requirements-bench.txt
	set -e; for g in $(GALLERIES); do $(VENV_PYTHON) -m scripts.$$g; done

# Opt-in robustness runs (not part of `make test` / CI; pytest markers, see
# pytest.ini); see docs/dev/robustness.md.
test-slow: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m pytest tests --run-slow

soak: $(VENV_STAMP) check-system
	$(VENV_PYTHON) -m pytest tests/test_soak.py --run-slow -s

fuzz: $(VENV_STAMP) check-system
	SOLIDWIRE_FUZZ_EXAMPLES=$(or $(FUZZ_EXAMPLES),500) $(VENV_PYTHON) -m pytest tests/test_fuzz.py -s

compat: check-system
	scripts/compat.sh $(COMPAT_VERSIONS)

clean:
	rm -rf out $(DIST_DIR) tests/output build/site
