"""Presets: named looks stored as JSON data, validated before anything changes.

A preset file is a JSON object::

    {"solidwire_preset": 1, "name": "Blueprint", "description": "...",
     "settings": {"thickness": 1.0, "wire_color": [1, 1, 1, 1], ...}}

``settings`` holds any subset of :data:`FIELDS` (the schema's preset settings) (built-in presets hold all of
them, so applying one gives the same look whatever was set before). An
optional ``"from_scene": ["fade_start", "fade_end"]`` marks the depth fade
range as measured when the preset is applied (from the view or camera to the
visible objects' bounding boxes, see :func:`apply`); the numbers in
``settings`` are then only what is kept when there is nothing to measure.
Files without it are read exactly as before (format version 1). Loading
never executes anything (no ``exec``/``eval``, unlike Blender's Python preset
files): the file is parsed as JSON with a size limit, every key, type and range
is checked, and only a fully valid preset is applied. Problems raise
:class:`PresetError` with one line that says which file and what is wrong.

Built-in presets ship in ``presets_builtin/`` next to this file and are read-only.
User presets live where Blender keeps every add-on's presets: ``presets/solidwire``
in the user scripts folder (``bpy.utils.user_resource('SCRIPTS')``). Not in the
add-on folder, which an upgrade replaces, and not in the extension's user
folder, which Blender deletes when the extension is uninstalled; and the same
folder whether the package runs as the installed extension or from a checkout
(scripts/render.py), so every entry point sees the same presets. Presets saved
by older versions in those places are moved here once.

Names: a preset's name is kept as typed (any script: "Böse Linien", "線画"),
inside its JSON. Its file name is the name's *key* (:func:`name_key`: letters
and digits of any script, case-folded, every other run of characters one
``_``), so names that differ only in case, spaces or punctuation ("My Look",
"my look", "My_Look") are the same preset. Saving or importing a user preset
whose key is a built-in's is refused (a user preset never shadows a built-in:
the menu, ``--preset NAME`` and render-farm jobs would otherwise mean different
looks by one name); replacing an existing user preset needs ``overwrite``.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import os
import shutil
import stat
import unicodedata
from dataclasses import dataclass, replace
from pathlib import Path

from ..core import schema

FORMAT_VERSION = 1
MAX_FILE_BYTES = 64 * 1024  # a preset is a few hundred bytes; refuse anything huge
BUILTIN_DIR = Path(__file__).resolve().parent / "presets_builtin"
_TOP_LEVEL_KEYS = {"solidwire_preset", "name", "description", "settings", "from_scene"}
MAX_NAME_LENGTH = 64
MAX_DESCRIPTION_LENGTH = 1000

# The settings a preset may hold, in the order they are applied (see
# schema.preset_settings: diagonal_mode before pattern_duty). Types and hard
# ranges are the schema's, the same the properties enforce.
FIELDS: dict[str, schema.Setting] = {s.name: s for s in schema.preset_settings()}

# Settings a preset may mark "from_scene" (measured when applied), all together.
FROM_SCENE_FIELDS = ("fade_start", "fade_end")


class PresetError(ValueError):
    """A preset that cannot be loaded or saved; str() is one line for the user."""


class PresetNotFound(PresetError):
    """No preset has the name asked for."""


@dataclass(frozen=True)
class Preset:
    name: str
    values: dict
    description: str = ""
    path: Path | None = None
    builtin: bool = False
    from_scene: tuple = ()  # FROM_SCENE_FIELDS when the fade range is measured on apply


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
            raise PresetError(f"unknown key '{min(unknown)}' (expected: {', '.join(sorted(_TOP_LEVEL_KEYS))})")
        if data.get("solidwire_preset") != FORMAT_VERSION:
            raise PresetError(f"'solidwire_preset' must be {FORMAT_VERSION} (the preset format version)")
        name = data.get("name")
        if not isinstance(name, str) or not name.strip() or len(name) > MAX_NAME_LENGTH:
            raise PresetError(f"'name' must be a non-empty string of at most {MAX_NAME_LENGTH} characters")
        description = data.get("description", "")
        if not isinstance(description, str) or len(description) > MAX_DESCRIPTION_LENGTH:
            raise PresetError(f"'description' must be a string of at most {MAX_DESCRIPTION_LENGTH} characters")
        settings = data.get("settings")
        if not isinstance(settings, dict) or not settings:
            raise PresetError("'settings' must be a non-empty object")
        values = {key: validate_value(key, value) for key, value in settings.items()}
        from_scene = _check_from_scene(data.get("from_scene", []))
    except PresetError as exc:
        raise PresetError(f"{source}: {exc}") from None
    return Preset(name=name.strip(), values=values, description=description, from_scene=from_scene)


def _check_from_scene(keys) -> tuple:
    if not isinstance(keys, list) or not all(isinstance(k, str) for k in keys):
        raise PresetError("'from_scene' must be a list of setting names")
    for key in keys:
        if key not in FIELDS:
            raise PresetError(f"unknown setting '{key}' in 'from_scene'")
        if key not in FROM_SCENE_FIELDS:
            raise PresetError(f"'{key}' cannot be taken from the scene (only {', '.join(FROM_SCENE_FIELDS)})")
    if keys and sorted(keys) != sorted(FROM_SCENE_FIELDS):
        raise PresetError(f"'from_scene' must name {' and '.join(FROM_SCENE_FIELDS)} once each")
    return FROM_SCENE_FIELDS if keys else ()


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
    return replace(parse(text, source=path.name), path=path, builtin=builtin)


# ------------------------------------------------------------------- storage


USER_SUBDIR = "presets/solidwire"


def user_dir(*, create: bool = True) -> Path:
    """Where user presets are saved: Blender's user ``presets/solidwire``
    folder (see the module notes). Presets found in the older places are
    moved here the first time it is asked for."""
    import bpy

    path = Path(bpy.utils.user_resource("SCRIPTS", path=USER_SUBDIR, create=create))
    _migrate_old_presets(path)
    return path


_migrated: set = set()


def old_user_dirs() -> list[Path]:
    """Where older versions kept user presets: the extension's user folder
    (when running as the installed extension) and a folder in Blender's
    config directory (when imported as a plain package)."""
    import bpy

    folders = [Path(bpy.utils.user_resource("CONFIG")) / "solidwire_presets"]
    parts = (__package__ or "").split(".")
    if parts[0] == "bl_ext" and len(parts) >= 3:
        try:
            folders.append(Path(bpy.utils.extension_path_user(".".join(parts[:3]), path="presets", create=False)))
        except (ValueError, RuntimeError):  # not a registered extension (any more)
            pass
    return folders


def _migrate_old_presets(target: Path) -> None:
    """Move preset files from :func:`old_user_dirs` into ``target``, once per
    folder and process. A file whose name is taken in ``target`` stays where
    it is (nothing is overwritten); a folder left empty is removed."""
    for folder in old_user_dirs():
        if folder in _migrated or folder == target:
            continue
        _migrated.add(folder)
        if not folder.is_dir():
            continue
        for old in sorted(folder.glob("*.json")):
            new = target / old.name
            if new.exists():
                continue
            try:
                target.mkdir(parents=True, exist_ok=True)
                shutil.move(str(old), str(new))
            except OSError as exc:
                print(f"SolidWire: could not move preset '{old.name}' to the presets folder: {exc.strerror or exc}")
        try:
            folder.rmdir()  # only when empty
        except OSError:
            pass


# Names Windows reserves for devices, with any extension.
_RESERVED_STEMS = {"con", "prn", "aux", "nul", *(f"com{i}" for i in range(10)), *(f"lpt{i}" for i in range(10))}
_MAX_STEM_BYTES = 120  # file names are at most 255 bytes on common file systems


def name_key(name: str) -> str:
    """What makes two preset names the same preset: the letters, digits and
    combining marks of any script, case-folded (NFKC), with every other run of
    characters one ``_``. "My Look", " my look " and "My_Look" -> "my_look";
    "Böse Linien" -> "böse_linien"; "線画" -> "線画". PresetError when
    nothing is left ("!!!", "../../")."""
    text = unicodedata.normalize("NFKC", name.strip()).casefold()
    kept = "".join(c if c.isalnum() or unicodedata.category(c).startswith("M") else " " for c in text)
    key = "_".join(kept.split())
    if not key:
        raise PresetError(f"preset name '{name.strip()}' has no letters or digits")
    return key


def filename_for(name: str) -> str:
    """A safe file name for a user preset: its :func:`name_key`, kept short
    enough for any file system and off Windows' device names. (The name
    itself is stored, unchanged, inside the file.)"""
    stem = name_key(name)
    if len(stem.encode("utf-8")) > _MAX_STEM_BYTES:
        digest = hashlib.sha1(stem.encode("utf-8")).hexdigest()[:8]
        stem = stem.encode("utf-8")[: _MAX_STEM_BYTES - 9].decode("utf-8", "ignore") + "_" + digest
    if stem in _RESERVED_STEMS:
        stem += "_"
    return stem + ".json"


def builtin_presets() -> list[Preset]:
    """Built-in presets, in file-name order (files are numbered)."""
    return [load(path, builtin=True) for path in sorted(BUILTIN_DIR.glob("*.json"))]


def _builtin_named(name: str) -> Preset | None:
    """The built-in preset whose name has the same key as ``name``."""
    key = name_key(name)
    return next((p for p in builtin_presets() if name_key(p.name) == key), None)


def user_presets() -> tuple[list[Preset], list[str]]:
    """(valid user presets, one-line messages about files that were skipped).

    A file named like a built-in preset (written by hand or by an older
    version) is skipped with a message, never shadowing the built-in."""
    presets, problems = [], []
    folder = user_dir(create=False)
    if folder.is_dir():
        builtin_keys = {name_key(p.name): p.name for p in builtin_presets()}
        for path in sorted(folder.glob("*.json")):
            try:
                preset = load(path)
            except PresetError as exc:
                problems.append(str(exc))
                continue
            clash = builtin_keys.get(name_key(preset.name))
            if clash is not None:
                problems.append(
                    f"{path.name}: '{preset.name}' is named like the built-in preset '{clash}' "
                    "and is not used (import it under another name)"
                )
                continue
            presets.append(preset)
    return presets, problems


def all_presets() -> list[Preset]:
    presets, _problems = user_presets()
    return builtin_presets() + presets


def _matching(presets: list[Preset], name: str) -> list[Preset]:
    """Presets called exactly ``name``, else those whose key is ``name``'s."""
    exact = [p for p in presets if p.name == name]
    if exact:
        return exact
    try:
        key = name_key(name)
    except PresetError:
        return []
    return [p for p in presets if name_key(p.name) == key]


def find(name: str) -> Preset:
    """The preset called ``name``: its exact name first, else the same name
    up to case, spaces and punctuation ("blueprint" finds "Blueprint"). User
    presets never share a built-in's name (see :func:`user_presets`)."""
    everything = all_presets()
    matches = _matching(everything, name)
    if not matches:
        raise PresetNotFound(f"no preset named '{name}'")
    return matches[0]


def unknown_preset_message(name: str, names: list[str]) -> str:
    """One line: no such preset, the close matches, and every name there is."""
    by_key = {}
    for known in names:
        try:
            by_key.setdefault(name_key(known), known)
        except PresetError:
            continue
    try:
        key = name_key(name)
    except PresetError:
        key = name.casefold()
    close = [by_key[k] for k in difflib.get_close_matches(key, list(by_key), n=3, cutoff=0.6)]
    hint = f"did you mean {' or '.join(repr(c) for c in close)}? " if close else ""
    listed = ", ".join(names) if names else "none"
    return f"no preset named '{name}' ({hint}presets: {listed})"


def user_preset_like(name: str) -> Preset | None:
    """The existing user preset that saving under ``name`` would replace
    (same :func:`name_key`), or None."""
    try:
        key = name_key(name)
    except PresetError:
        return None
    presets, _problems = user_presets()
    return next((p for p in presets if name_key(p.name) == key), None)


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


def apply(preset: Preset, props, *, depth_range=None) -> str:
    """Set ``props`` from an already validated preset (all keys checked at
    parse time, so this cannot fail half-way on bad data).

    For a preset whose fade range is ``from_scene``, ``depth_range()`` (called
    only then) gives the (nearest, farthest) view depth of the visible
    objects, or None when there is nothing to measure; the preset's own
    numbers are kept then (and when no ``depth_range`` is given). Returns a
    one-line note about what was measured or kept ("" for other presets)."""
    values = dict(preset.values)
    note = ""
    if preset.from_scene:
        measured = depth_range() if depth_range is not None else None
        if measured is not None:
            try:  # through the schema, as any preset value
                start, end = (FIELDS[key].check(value) for key, value in zip(FROM_SCENE_FIELDS, measured))
            except ValueError:  # beyond the settings' range: nothing usable
                measured = None
        if measured is None:
            kept = [values.get(key, getattr(props, key)) for key in FROM_SCENE_FIELDS]
            note = f"nothing visible to measure the fade range from; kept {kept[0]:g} to {kept[1]:g}"
        else:
            values["fade_start"], values["fade_end"] = start, end
            note = f"fade range {start:.3g} to {end:.3g}, measured to the visible objects"
    for key in FIELDS:  # FIELDS order: diagonal_mode before pattern_duty
        if key in values:
            setattr(props, key, values[key])
    return note


def to_json(name: str, values: dict, description: str = "", from_scene: tuple = ()) -> str:
    data = {
        "solidwire_preset": FORMAT_VERSION,
        "name": name,
        "description": description,
        "settings": {key: list(v) if isinstance(v, tuple) else v for key, v in values.items()},
    }
    if from_scene:  # only then: other presets stay readable by older versions
        data["from_scene"] = list(from_scene)
    # ensure_ascii=False: a name in any script stays readable in the file.
    return json.dumps(data, indent=2, ensure_ascii=False) + "\n"


def _write(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` whole or not at all (PresetError, one line)."""
    tmp = path.with_name(path.name + ".tmp")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)  # never leave a half-written preset behind
    except OSError as exc:
        raise PresetError(f"{path.name}: cannot write ({exc.strerror or exc})") from None
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def _checked_text(preset: Preset, source: str) -> str:
    """The preset's JSON, validated as a file would be."""
    text = to_json(preset.name, preset.values, preset.description, preset.from_scene)
    parse(text, source=source)
    return text


def save_preset(preset: Preset, *, overwrite: bool = False) -> Path:
    """Write ``preset`` as a user preset and return its path.

    Refused (PresetError, one line) when its name is a built-in's up to case,
    spaces and punctuation, or when a user preset of that name exists and
    ``overwrite`` is not set. The text is validated before it is written."""
    name = preset.name.strip()
    preset = replace(preset, name=name)
    text = _checked_text(preset, name or "preset")
    builtin = _builtin_named(name)  # PresetError when the name has no letters or digits
    if builtin is not None:
        raise PresetError(f"'{name}' is the name of the built-in preset '{builtin.name}'; choose another name")
    existing = user_preset_like(name)
    if existing is not None and not overwrite:
        raise PresetError(f"a user preset named '{existing.name}' exists; choose another name or overwrite it")
    path = existing.path if existing is not None else user_dir() / filename_for(name)
    if existing is None and path.exists() and not overwrite:  # an unreadable file of that name
        raise PresetError(f"'{path.name}' exists in the presets folder; choose another name or overwrite it")
    return _write(path, text)


def save(name: str, props, *, description: str = "", overwrite: bool = False) -> Path:
    """Write the current settings as a user preset called ``name`` (rules:
    :func:`save_preset`) and return its path."""
    return save_preset(Preset(name.strip(), values_of(props), description), overwrite=overwrite)


def export(path: Path, preset: Preset) -> Path:
    """Write ``preset`` to the file ``path`` (any folder, e.g. to share it),
    replacing that file; validated first, as a loaded file would be."""
    path = Path(path)
    return _write(path, _checked_text(preset, path.name))


def import_file(path: Path, *, name: str = "", overwrite: bool = False) -> Preset:
    """Add the preset file ``path`` to the user presets, as ``name`` when
    given (else the name inside the file). The file is validated completely
    (:func:`load`); name rules as for :func:`save_preset`. Returns the preset
    as saved."""
    preset = load(Path(path))
    if name.strip():
        preset = replace(preset, name=name.strip())
    saved = save_preset(replace(preset, path=None, builtin=False), overwrite=overwrite)
    return load(saved)


def remove(name: str) -> Path:
    """Delete the user preset called ``name`` (built-ins cannot be removed)."""
    presets, _problems = user_presets()
    matches = _matching(presets, name)
    if matches:
        matches[0].path.unlink()
        return matches[0].path
    if _matching(builtin_presets(), name):
        raise PresetError(f"'{name}' is a built-in preset and cannot be removed")
    raise PresetError(f"no user preset named '{name}'")
