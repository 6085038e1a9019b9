"""Test set-up shared by every test file.

The tests run on the PyPI ``bpy`` module (one Blender per pytest process).
pytest.ini puts the repository root on sys.path, so ``import solidwire_addon``
works as inside the installed extension (relative imports only) and shared
helpers come from ``tests.support``. Blender's user resources point at a
temporary folder so nothing touches the user's own configuration.

The tests in ``tests/pure/`` need no Blender (plain numpy on core's
modules): Blender starts, and the add-on is registered, only for the other
test files, so ``pytest tests/pure`` runs in a Python without ``bpy``.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest

# Must be set before bpy is imported (subprocesses that start Blender inherit it).
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

ROOT = Path(__file__).resolve().parent.parent
OUTPUT_DIR = ROOT / "tests" / "output"
PURE_DIR = ROOT / "tests" / "pure"


def needs_blender(path: Path) -> bool:
    return PURE_DIR not in Path(path).parents


def pytest_collectstart(collector):
    """Start Blender before the first test file that needs it is imported
    (its module-level imports may use ``bpy`` and ``gpu``)."""
    if isinstance(collector, pytest.Module) and needs_blender(collector.path):
        import bpy  # noqa: F401  (before the test file, once BLENDER_USER_RESOURCES is set)


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


@pytest.fixture(scope="session")
def addon():
    """The add-on registered for the whole session (unregistered at the end),
    with the GPU usable from the first test on."""
    import solidwire_addon
    from solidwire_addon.blender.gpu_context import ensure_gpu

    solidwire_addon.register()
    ensure_gpu()
    yield solidwire_addon
    solidwire_addon.unregister()


@pytest.fixture(scope="module", autouse=True)
def _addon_registered(request):
    """Every test file outside tests/pure/ runs with the add-on registered
    (module-scoped and autouse: before any fixture of the file's own)."""
    if needs_blender(request.path):
        request.getfixturevalue("addon")


@pytest.fixture(autouse=True)
def _messages_said_afresh():
    """Every test starts with no one-line message said yet: a message is said
    once per session (core/log.py), so a test that expects one must not
    depend on whether an earlier test, in whatever order, said it first."""
    from solidwire_addon.core import log

    log.forget()


@pytest.fixture
def output_dir() -> Path:
    """Where tests write images a person can look at (ignored by git)."""
    OUTPUT_DIR.mkdir(parents=True, exist_ok=True)
    return OUTPUT_DIR
