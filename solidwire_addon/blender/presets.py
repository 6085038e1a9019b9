"""Presets: named looks stored as JSON data, validated before anything changes.

A preset file is a JSON object::

    {"solidwire_preset": 1, "name": "Blueprint", "description": "...",
     "settings": {"thickness": 1.0, "wire_color": [1, 1, 1, 1], ...}}

``settings`` holds any subset of :data:`FIELDS` (the schema's preset settings) (built-in presets hold all of
them, so applying one gives the same look whatever was set before). Loading
never executes anything (no ``exec``/``eval``, unlike Blender's Python preset
files): the file is parsed as JSON with a size limit, every key, type and range
is checked, and only a fully valid preset is applied. Problems raise
:class:`PresetError` with one line that says which file and what is wrong.

Built-in presets ship in ``presets_builtin/`` next to this file and are read-only.
User presets live in the extension's user directory
(``bpy.utils.extension_path_user``), never inside the add-on folder, which an
upgrade replaces.
"""

from __future__ import annotations

import json
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

from ..core import schema

FORMAT_VERSION = 1
MAX_FILE_BYTES = 64 * 1024  # a preset is a few hundred bytes; refuse anything huge
BUILTIN_DIR = Path(__file__).resolve().parent / "presets_builtin"
_TOP_LEVEL_KEYS = {"solidwire_preset", "name", "description", "settings"}
MAX_NAME_LENGTH = 64

# The settings a preset may hold, in the order they are applied (see
# schema.preset_settings: diagonal_mode before pattern_duty). Types and hard
# ranges are the schema's, the same the properties enforce.
FIELDS: dict[str, schema.Setting] = {s.name: s for s in schema.preset_settings()}


class PresetError(ValueError):
    """A preset that cannot be loaded or saved; str() is one line for the user."""


@dataclass(frozen=True)
class Preset:
    name: str
    values: dict
    description: str = ""
    path: Path | None = None
    builtin: bool = False


# ---------------------------------------------------------------- validation


def validate_value(key: str, value):
    """The value to apply for ``key``, or PresetError."""
    setting = FIELDS.get(key)
    if setting is None:
        raise PresetError(f"unknown setting '{key}' (known: {', '.join(FIELDS)})")
    try:
        return setting.check(value)
    except ValueError as exc:
        raise PresetError(str(exc)) from None


def _reject_constant(token: str):
    raise PresetError(f"'{token}' is not allowed in a preset")


def _no_duplicate_keys(pairs):
    result = {}
    for key, value in pairs:
        if key in result:
            raise PresetError(f"key '{key}' appears twice")
        result[key] = value
    return result


def parse(text: str, *, source: str = "preset") -> Preset:
    """Validate preset JSON text completely; return the Preset or raise
    PresetError('<source>: <what is wrong>')."""
    try:
        if len(text.encode("utf-8")) > MAX_FILE_BYTES:
            raise PresetError(f"file is larger than {MAX_FILE_BYTES // 1024} KiB")
        try:
            data = json.loads(text, parse_constant=_reject_constant, object_pairs_hook=_no_duplicate_keys)
        except json.JSONDecodeError as exc:
            raise PresetError(f"not valid JSON ({exc.msg} at line {exc.lineno} column {exc.colno})") from None
        except RecursionError:
            raise PresetError("nested too deeply") from None
        except ValueError as exc:  # e.g. an integer longer than Python converts
            raise PresetError(f"not valid JSON ({str(exc).split(';')[0]})") from None
        if not isinstance(data, dict):
            raise PresetError("must be a JSON object")
        unknown = set(data) - _TOP_LEVEL_KEYS
        if unknown:
            raise PresetError(f"unknown key '{sorted(unknown)[0]}' (expected: {', '.join(sorted(_TOP_LEVEL_KEYS))})")
        if data.get("solidwire_preset") != FORMAT_VERSION:
            raise PresetError(f"'solidwire_preset' must be {FORMAT_VERSION} (the preset format version)")
        name = data.get("name")
        if not isinstance(name, str) or not name.strip() or len(name) > MAX_NAME_LENGTH:
            raise PresetError(f"'name' must be a non-empty string of at most {MAX_NAME_LENGTH} characters")
        description = data.get("description", "")
        if not isinstance(description, str) or len(description) > 1000:
            raise PresetError("'description' must be a string of at most 1000 characters")
        settings = data.get("settings")
        if not isinstance(settings, dict) or not settings:
            raise PresetError("'settings' must be a non-empty object")
        values = {key: validate_value(key, value) for key, value in settings.items()}
    except PresetError as exc:
        raise PresetError(f"{source}: {exc}") from None
    return Preset(name=name.strip(), values=values, description=description)


def load(path: Path, *, builtin: bool = False) -> Preset:
    path = Path(path)
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):  # a FIFO or device would block or never end
            raise PresetError(f"{path.name}: not a regular file")
        size = info.st_size
        if size > MAX_FILE_BYTES:
            raise PresetError(f"{path.name}: file is larger than {MAX_FILE_BYTES // 1024} KiB")
        with path.open("rb") as handle:
            raw = handle.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise PresetError(f"{path.name}: cannot read ({exc.strerror})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise PresetError(f"{path.name}: not UTF-8 text") from None
    preset = parse(text, source=path.name)
    return Preset(preset.name, preset.values, preset.description, path, builtin)


# ------------------------------------------------------------------- storage


def user_dir(*, create: bool = True) -> Path:
    """Where user presets are saved.

    Inside an installed extension: ``extension_path_user(<extension>)/presets``.
    Imported as a plain package (tests, scripts), there is no extension, so a
    folder in Blender's user config directory is used instead; never the
    add-on folder."""
    import bpy

    package = __package__ or ""
    parts = package.split(".")
    if parts[0] == "bl_ext" and len(parts) >= 3:
        return Path(bpy.utils.extension_path_user(".".join(parts[:3]), path="presets", create=create))
    path = Path(bpy.utils.user_resource("CONFIG")) / "solidwire_presets"
    if create:
        path.mkdir(parents=True, exist_ok=True)
    return path


def filename_for(name: str) -> str:
    stem = re.sub(r"[^A-Za-z0-9]+", "_", name.strip()).strip("_").lower()
    if not stem:
        raise PresetError(f"preset name '{name}' has no letters or digits")
    return stem + ".json"


def builtin_presets() -> list[Preset]:
    """Built-in presets, in file-name order (files are numbered)."""
    return [load(path, builtin=True) for path in sorted(BUILTIN_DIR.glob("*.json"))]


def user_presets() -> tuple[list[Preset], list[str]]:
    """(valid user presets, one-line messages about files that were skipped)."""
    presets, problems = [], []
    folder = user_dir(create=False)
    if folder.is_dir():
        for path in sorted(folder.glob("*.json")):
            try:
                presets.append(load(path))
            except PresetError as exc:
                problems.append(str(exc))
    return presets, problems


def all_presets() -> list[Preset]:
    presets, _problems = user_presets()
    return builtin_presets() + presets


def find(name: str) -> Preset:
    """User presets shadow built-ins of the same name."""
    matches = [p for p in all_presets() if p.name == name]
    if not matches:
        raise PresetError(f"no preset named '{name}'")
    return matches[-1]


# ------------------------------------------------------------- apply / save


def values_of(props) -> dict:
    """The preset values of a ``scene.solidwire`` property group."""
    values = {}
    for key, setting in FIELDS.items():
        value = getattr(props, key)
        if setting.kind == schema.COLOR:
            value = [round(float(c), 6) for c in value]
        elif setting.kind == schema.FLOAT:
            value = round(float(value), 6)
        values[key] = value
    return values


def apply(preset: Preset, props) -> None:
    """Set ``props`` from an already validated preset (all keys checked at
    parse time, so this cannot fail half-way on bad data)."""
    for key in FIELDS:  # FIELDS order: diagonal_mode before pattern_duty
        if key in preset.values:
            setattr(props, key, preset.values[key])


def to_json(name: str, values: dict, description: str = "") -> str:
    data = {"solidwire_preset": FORMAT_VERSION, "name": name, "description": description, "settings": values}
    return json.dumps(data, indent=2) + "\n"


def save(name: str, props, *, description: str = "") -> Path:
    """Write the current settings as a user preset (replacing one of the same
    name) and return its path. The text is validated before it is written."""
    name = name.strip()
    text = to_json(name, values_of(props), description)
    parse(text, source=name)
    path = user_dir() / filename_for(name)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)  # never leave a half-written preset behind
    return path


def remove(name: str) -> Path:
    """Delete the user preset called ``name`` (built-ins cannot be removed)."""
    presets, _problems = user_presets()
    for preset in presets:
        if preset.name == name:
            preset.path.unlink()
            return preset.path
    if any(p.name == name for p in builtin_presets()):
        raise PresetError(f"'{name}' is a built-in preset and cannot be removed")
    raise PresetError(f"no user preset named '{name}'")
