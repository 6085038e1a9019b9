"""Test set-up shared by every test file.

The tests run on the PyPI ``bpy`` module (one Blender per pytest process).
The repository root is put on sys.path so ``import solidwire_addon`` works the
same way it does inside the installed extension (relative imports only), and
Blender's user resources point at a temporary folder so nothing touches the
user's own configuration.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUTPUT_DIR = ROOT / "tests" / "output"

# Must be set before bpy is imported.
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import bpy  # noqa: E402
import pytest  # noqa: E402

import solidwire_addon  # noqa: E402


@pytest.fixture(scope="session", autouse=True)
def addon():
    """The add-on registered for the whole session (unregistered at the end)."""
    solidwire_addon.register()
    yield solidwire_addon
    solidwire_addon.unregister()


@pytest.fixture
def output_dir() -> Path:
    """Where tests write images a person can look at (ignored by git)."""
    OUTPUT_DIR.mkdir(parents=True, exist_ok=True)
    return OUTPUT_DIR
