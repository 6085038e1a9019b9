"""Can an image be written there? Checked before any long render, by the
command line and by the operators alike, so a bad path costs no render.
(Plain Python: no Blender.)"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


class OutputError(ValueError):
    """The output path cannot be written: one line for the user."""


def check_output_folder(directory: Path, *, create: bool = True) -> None:
    """Create the folder if needed (as Blender does) and prove it writable.
    With ``create=False`` nothing is left behind: a missing folder is checked
    through the nearest folder that exists (where it would be created)."""
    directory = Path(directory)
    existing = directory
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(f"cannot write to '{directory}': '{existing}' is a file, not a folder")
    if create:
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"cannot create output folder '{directory}': {exc.strerror}") from None
        existing = directory
    try:
        # A real write, not os.access: also right for read-only mounts and root.
        with tempfile.NamedTemporaryFile(dir=existing, prefix=".solidwire-write-test-"):
            pass
    except OSError as exc:
        if existing == directory:
            raise OutputError(f"cannot write to '{directory}': {exc.strerror}") from None
        raise OutputError(f"cannot create output folder '{directory}': {exc.strerror} in '{existing}'") from None


def check_output(path: Path, *, create: bool = True) -> None:
    """Fail before rendering if the image cannot be written at ``path``."""
    path = Path(path)
    if path.is_dir():
        raise OutputError(f"output '{path}' is a directory")
    check_output_folder(path.parent, create=create)
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputError(f"cannot overwrite '{path}': permission denied")
