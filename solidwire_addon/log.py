"""User-facing messages: one clear line, printed once per cause."""

from __future__ import annotations

import sys

_said: set = set()


def warn_once(key, message: str) -> None:
    if key in _said:
        return
    _said.add(key)
    print(message, file=sys.stderr)


def forget() -> None:
    """Let messages be said again (new file loaded, add-on re-registered)."""
    _said.clear()
