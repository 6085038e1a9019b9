"""Settings that hold a value no panel could set: NaN stored by a script or
a driver (Blender itself clamps infinities and out-of-range numbers to the
property's hard limits, but not NaN).

The draw path's snapshot (core/settings.py) already falls back to the
default for such a value; here the stored property is put right as well,
so the panel, presets saved from it and the next frame agree with what was
drawn, and the user hears about it once, in Blender's report:

* a number that is not finite becomes its default;
* a colour is repaired component by component: a NaN component takes the
  default's component, the others are clamped to the hard range one by one
  (a fill colour (-1, 2, NaN) becomes (0, 1, default blue)), so the colour
  stays the one the user set as far as it can.

Writing properties is only safe on Blender's main thread (update callbacks
tag redraws); a render job running on its own thread leaves the write to a
timer, which runs on the main thread.
"""

from __future__ import annotations

import math
import threading

import bpy

from ..core import schema
from ..core.log import warn_once
from ..core.settings import DrawSettings


def _fixed(setting: schema.Setting, value):
    """The repaired value of ``setting`` (None when ``value`` is fine)."""
    if setting.kind == schema.FLOAT:
        value = float(value)
        return None if math.isfinite(value) else float(setting.default)
    if setting.kind == schema.COLOR:
        values = tuple(float(c) for c in value)
        fixed = tuple(
            float(d) if math.isnan(c) else min(max(c, setting.minimum), setting.maximum)
            for c, d in zip(values, setting.default)
        )
        # NaN != NaN, so a colour holding one always counts as changed.
        return None if fixed == values else fixed
    return None


def _shown(value) -> str:
    if isinstance(value, tuple):
        return "(" + ", ".join(f"{c:g}" for c in value) + ")"
    return f"{value:g}"


def find_repairs(props, scope: str = schema.SCENE) -> dict:
    """{name: (stored value, repaired value)} of every setting of ``scope``
    in ``props`` that holds a non-finite or out-of-range number."""
    repairs = {}
    for setting in schema.settings_in(scope):
        if setting.kind not in (schema.FLOAT, schema.COLOR):
            continue
        value = getattr(props, setting.name)
        fixed = _fixed(setting, value)
        if fixed is not None:
            stored = tuple(float(c) for c in value) if setting.kind == schema.COLOR else float(value)
            repairs[setting.name] = (stored, fixed)
    return repairs


def message(owner: str, name: str, stored, fixed) -> str:
    """The one line that says what was repaired."""
    if isinstance(stored, float):
        return f"SolidWire: {owner} setting '{name}' is {stored:g}, not a finite number; reset to its default {fixed:g}"
    return (
        f"SolidWire: {owner} setting '{name}' = {_shown(stored)} has a NaN or out-of-range component; "
        f"reset to {_shown(fixed)}"
    )


def store(props, repairs: dict, *, defer: bool = False) -> None:
    """Write the repaired values into ``props`` now (main thread) or from a
    timer (a render thread, or ``defer``: a draw handler, which must not
    change data while Blender draws). A property that cannot be written
    (the scene gone) keeps its value: the snapshot's fallback still draws
    the default."""

    def write():
        try:
            for name, (_stored, fixed) in repairs.items():
                setattr(props, name, fixed)
        except (AttributeError, ReferenceError, RuntimeError, TypeError):
            pass
        # Returning None: a timer that runs once.

    if not defer and threading.current_thread() is threading.main_thread():
        write()
    else:
        run_later(write)


def run_later(function) -> None:
    """Run ``function`` once from Blender's main loop (a timer)."""
    bpy.app.timers.register(function, first_interval=0.0)


# Messages waiting for the timer that reports them (a viewport redraws many
# times before it runs; each message is reported once).
_pending: set = set()


def report_later(lines) -> None:
    """Say ``lines`` in Blender's report (status bar and Info editor) from a
    timer, for callers that have no operator or engine to report through
    (the overlay's draw handler); the console hears them at once."""
    new = [line for line in lines if line not in _pending]
    if not new:
        return
    for line in new:
        warn_once(("repaired", line), line)
    _pending.update(new)

    def say():
        for line in new:
            _pending.discard(line)
            try:
                bpy.ops.solidwire.report_message(message=line)
            except (AttributeError, RuntimeError):
                pass  # no window to report in (already said on the console)

    run_later(say)


def checked_snapshot(scene, stored_props=None, *, defer: bool = False) -> tuple[DrawSettings, list[str]]:
    """(DrawSettings, messages) of ``scene.solidwire`` with every bad value
    repaired; the repairs are written into ``stored_props`` (default: the
    same settings; a render passes the original scene's, since the scene it
    draws is the depsgraph's copy), later with ``defer`` (see store)."""
    props = scene.solidwire
    repairs = find_repairs(props)
    if not repairs:
        return props.snapshot(), []
    settings = DrawSettings.from_properties(_Patched(props, repairs))
    store(props if stored_props is None else stored_props, repairs, defer=defer)
    return settings, [message(f"scene '{scene.name}'", name, *values) for name, values in repairs.items()]


class SOLIDWIRE_OT_report_message(bpy.types.Operator):
    """Put one line in Blender's report (used from timers)"""

    bl_idname = "solidwire.report_message"
    bl_label = "SolidWire Message"
    bl_options = {"INTERNAL"}

    message: bpy.props.StringProperty()

    def execute(self, _context):
        self.report({"WARNING"}, self.message)
        return {"FINISHED"}


classes = (SOLIDWIRE_OT_report_message,)


class _Patched:
    """``props`` as seen with the repaired values in place."""

    def __init__(self, props, repairs):
        self._props, self._repairs = props, repairs

    def __getattr__(self, name):
        repair = self._repairs.get(name)
        return repair[1] if repair is not None else getattr(self._props, name)
