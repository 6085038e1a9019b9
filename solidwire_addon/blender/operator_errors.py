"""One guard for every operator's ``execute`` / ``invoke``: an unexpected
exception ends as a one-line report, never as a traceback (the operators of
ops.py and ops_composite.py share it)."""

from __future__ import annotations

import functools

from ..core.log import one_line


def one_line_errors(method):
    """Wrap an operator's ``execute`` / ``invoke``: an unexpected exception is
    reported as one line (``bpy.ops`` raises RuntimeError with it) and the
    operator is cancelled, instead of Blender printing a traceback. Expected
    problems are checked and reported by the operators themselves."""

    def run(self, *args):
        try:
            return method(self, *args)
        except Exception as exc:  # noqa: BLE001 - no traceback from an operator
            message = one_line(exc)
            self.report({"ERROR"}, f"SolidWire: {self.bl_label} failed: {type(exc).__name__}: {message}")
            return {"CANCELLED"}

    # Blender checks the argument count of execute (self, context) and
    # invoke (self, context, event), so the wrapper keeps it.
    if method.__code__.co_argcount == 3:

        def guarded(self, context, event):
            return run(self, context, event)
    else:

        def guarded(self, context):
            return run(self, context)

    return functools.wraps(method)(guarded)
