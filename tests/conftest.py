"""Test set-up shared by every test file.

The tests run on the PyPI ``bpy`` module (one Blender per pytest process).
pytest.ini puts the repository root on sys.path, so ``import solidwire_addon``
works as inside the installed extension (relative imports only) and shared
helpers come from ``tests.support``. Blender's user resources point at a
temporary folder so nothing touches the user's own configuration.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

# Must be set before bpy is imported.
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

import bpy  # noqa: F401  (first, once BLENDER_USER_RESOURCES is set)
import pytest

import solidwire_addon
from solidwire_addon.blender.gpu_context import ensure_gpu

ROOT = Path(__file__).resolve().parent.parent
OUTPUT_DIR = ROOT / "tests" / "output"


# Opt-in markers (pytest.ini): each runs only with its option, or with the
# environment variable older scripts and habits set.
OPT_IN = {
    "slow": ("--run-slow", "SOLIDWIRE_SLOW"),
    "eevee": ("--run-eevee", "SOLIDWIRE_TEST_EEVEE"),
}


def pytest_addoption(parser):
    for marker, (option, variable) in OPT_IN.items():
        parser.addoption(
            option,
            action="store_true",
            default=False,
            help=f"also run the tests marked '{marker}' (or set {variable}=1)",
        )


def pytest_collection_modifyitems(config, items):
    for marker, (option, variable) in OPT_IN.items():
        if config.getoption(option) or os.environ.get(variable, "") not in ("", "0"):
            continue
        skip = pytest.mark.skip(reason=f"opt-in '{marker}' test: run with {option} ({variable}=1)")
        for item in items:
            if marker in item.keywords:
                item.add_marker(skip)


@pytest.fixture(scope="session", autouse=True)
def addon():
    """The add-on registered for the whole session (unregistered at the end),
    with the GPU usable from the first test on."""
    solidwire_addon.register()
    ensure_gpu()
    yield solidwire_addon
    solidwire_addon.unregister()


@pytest.fixture
def output_dir() -> Path:
    """Where tests write images a person can look at (ignored by git)."""
    OUTPUT_DIR.mkdir(parents=True, exist_ok=True)
    return OUTPUT_DIR
