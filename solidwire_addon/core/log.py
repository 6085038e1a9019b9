"""User-facing messages: one clear line, printed once per cause."""

from __future__ import annotations

import sys

_said: set = set()
# A scene with thousands of broken objects, or an error whose text changes
# every redraw, must not flood the console (nor grow this set) forever.
MAX_MESSAGES = 100
_SUPPRESSED = ("solidwire", "suppressed")


def one_line(exc: BaseException) -> str:
    """An exception's text as one line (a message box, a report or a shell's
    ``solidwire: error: ...`` shows one line; Blender's and the OS's messages
    can span several), or its type's name when it has no text."""
    return " ".join(str(exc).split()) or type(exc).__name__


def warn_once(key, message: str) -> None:
    if key in _said:
        return
    if len(_said) >= MAX_MESSAGES:
        if _SUPPRESSED not in _said:
            _said.add(_SUPPRESSED)
            print(f"SolidWire: more than {MAX_MESSAGES} messages; further ones are not shown", file=sys.stderr)
        return
    _said.add(key)
    print(message, file=sys.stderr)


def forget() -> None:
    """Let messages be said again (new file loaded, add-on re-registered)."""
    _said.clear()
