"""The command line: render a .blend with SolidWire, as Blender's own
command line does, from a shell or a render farm.

    blender -c solidwire render SCENE.blend [options]       (the extension)
    python scripts/render.py SCENE.blend [options]          (the bpy module)
    blender -b SCENE.blend --python scripts/render.py -- [options]

Blender's conventions: ``-o`` is optional (the scene's own output path,
``#`` and ``//`` filled in as Blender fills them); ``-f N`` renders frame N,
``-a`` the scene's frame range with its frame step, ``-s``/``-e``/``-j``
override start, end and step. ``--preset NAME|FILE`` applies a preset before
the other options; every look option comes from the settings schema and
overrides the scene's settings for this render only (the .blend is never
saved). ``--progress json`` prints one JSON object per frame for log parsers.

Images are rendered through the real engine (``scene.render.engine =
'SOLIDWIRE'`` and ``bpy.ops.render.render(write_still=True)``), so they are
the images ``blender -b SCENE.blend -E SOLIDWIRE -f 1`` writes.

Expected problems (missing or unreadable file, no camera, unwritable output,
bad option values) end with one line ``solidwire: error: ...`` on stderr and
exit code 2, before anything is rendered or written; a failed render exits
with code 1; SIGINT and SIGTERM stop after the frame in progress with 130
and 143. Frames appear under their names only when complete (a temporary
name, then a rename), a failed run leaves no folder it made, and the
scene's Overwrite and Placeholders settings work as in Blender's own
animation render. docs/user/command-line-pipeline.md has the details.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

import bpy

from ..core import compat, output, schema
from ..core.ids import ENGINE_ID, EXTENSION_ID
from ..core.log import one_line
from . import composite, presets, runtime
from .fade_range import camera_fade_range

EXIT_USAGE = 2
EXIT_FAILURE = 1

# Output formats chosen by the file extension of -o.
FILE_FORMATS = {
    ".png": "PNG",
    ".jpg": "JPEG",
    ".jpeg": "JPEG",
    ".tif": "TIFF",
    ".tiff": "TIFF",
    ".exr": "OPEN_EXR",
    ".bmp": "BMP",
    ".webp": "WEBP",
}
FORMATS_WITH_ALPHA = {"PNG", "TIFF", "OPEN_EXR", "WEBP"}

# Blend files start with "BLENDER"; Blender also writes them compressed.
BLEND_MAGICS = (b"BLENDER", b"\x28\xb5\x2f\xfd", b"\x1f\x8b")

# Metavars of float options by property subtype.
_METAVARS = {"PIXEL": "PX", "DISTANCE": "UNITS", "FACTOR": "Q"}


class UsageError(Exception):
    """An expected problem the user can fix: one line, exit code 2."""


class RenderFailed(Exception):
    """The engine could not render: one line, exit code 1."""


# -- arguments -----------------------------------------------------------------


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage dump
        raise UsageError(message)


def _color(text: str) -> tuple:
    """'R,G,B[,A]' with components in 0..1, or '#RRGGBB[AA]'."""
    text = text.strip()
    if text.startswith("#"):
        digits = text[1:]
        if len(digits) not in (6, 8) or not re.fullmatch(r"[0-9a-fA-F]+", digits):
            raise argparse.ArgumentTypeError(f"'{text}' is not a colour (#RRGGBB or #RRGGBBAA)")
        values = [int(digits[i : i + 2], 16) / 255.0 for i in range(0, len(digits), 2)]
    else:
        try:
            values = [float(part) for part in text.split(",")]
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a colour (R,G,B[,A] with values 0..1)") from None
        if len(values) not in (3, 4):
            raise argparse.ArgumentTypeError(f"'{text}' needs 3 or 4 components (R,G,B[,A])")
        if not all(math.isfinite(v) and 0.0 <= v <= 1.0 for v in values):
            raise argparse.ArgumentTypeError(f"'{text}': colour components must be between 0 and 1")
    if len(values) == 3:
        values.append(1.0)
    return tuple(values)


def _finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
    return value


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"'{text}' must be at least 1")
    return value


def _frame_range(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(-?\d+)\s*(?:-\s*(-?\d+)\s*)?", text)
    if not match:
        raise argparse.ArgumentTypeError(f"'{text}' is not a frame or frame range (N or A-B)")
    first = int(match.group(1))
    last = int(match.group(2)) if match.group(2) is not None else first
    if last < first:
        raise argparse.ArgumentTypeError(f"frame range '{text}' ends before it starts")
    return first, last


# Blender's frame limits (MINAFRAME, MAXFRAME): every frame number given on
# its command line is clamped into them.
MIN_FRAME = -1048574
MAX_FRAME = 1048574

_RELATIVE = re.compile(r"[+-]?\d+")


class Relative(tuple):
    """A frame number as Blender's command line reads it: ``N`` is frame N,
    ``+N`` counts from one anchor and ``-N`` from another (which ones depends
    on the option), resolved once the scene is open."""

    def __new__(cls, text: str):
        text = text.strip()
        if not _RELATIVE.fullmatch(text):
            raise ValueError(text)
        return super().__new__(cls, (text[0] if text[0] in "+-" else "", int(text.lstrip("+-"))))

    def resolve(self, plus: int, minus: int) -> int:
        # Blender: "+N" is plus + N, "-N" is minus - N + 1 (creator_args'
        # parse_int_relative), then clamped to the frame limits.
        sign, number = self
        value = plus + number if sign == "+" else minus - number + 1 if sign == "-" else number
        return min(max(value, MIN_FRAME), MAX_FRAME)


def _relative_frame(text: str) -> Relative:
    try:
        return Relative(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a frame number (N, +N or -N)") from None


def _frame_list(text: str) -> list[tuple[Relative, Relative]]:
    """Blender's -f syntax: a comma list of 'N' and 'A..B' items, each number
    absolute or relative ('+N' from the scene's start, '-N' from its end)."""
    items = []
    for part in text.split(","):
        first, dots, last = part.partition("..")
        try:
            start = Relative(first)
            items.append((start, Relative(last) if dots else start))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"'{text}' is not a frame list (N, A..B or a comma list of them; +N and -N count from "
                "the scene's start and end)"
            ) from None
    return items


def _frame_step(text: str) -> int:
    value = _positive_int(text)
    return min(value, MAX_FRAME)  # clamped as Blender clamps -j


# Options whose value may start with "-" (Blender's "-f -1"): argparse would
# read such a value as an option, so it is joined to its long option first.
_SIGNED_VALUE_OPTIONS = {
    "-f": "--render-frame",
    "--render-frame": "--render-frame",
    "-s": "--frame-start",
    "--frame-start": "--frame-start",
    "-e": "--frame-end",
    "--frame-end": "--frame-end",
}


def _join_signed_values(arguments: list[str]) -> list[str]:
    joined, index = [], 0
    while index < len(arguments):
        word = arguments[index]
        option = _SIGNED_VALUE_OPTIONS.get(word)
        if (
            option is not None
            and index + 1 < len(arguments)
            and arguments[index + 1].startswith("-")
            and arguments[index + 1][1:2].isdigit()
        ):
            joined.append(f"{option}={arguments[index + 1]}")
            index += 2
            continue
        joined.append(word)
        index += 1
    return joined


def _add_setting_option(group, setting: schema.Setting) -> None:
    """The option of one schema setting (its flag, parser and help)."""
    help_text = setting.description[0].lower() + setting.description[1:]
    if setting.kind == schema.BOOL:
        group.add_argument(
            setting.flag, dest=setting.name, action=argparse.BooleanOptionalAction, default=None, help=help_text
        )
    elif setting.kind == schema.ENUM:
        # Upper-case identifiers take any case; names (matcaps) as written.
        upper = all(choice == choice.upper() for choice in setting.choices)
        group.add_argument(
            setting.flag, dest=setting.name, choices=setting.choices, type=str.upper if upper else str, help=help_text
        )
    elif setting.kind == schema.COLOR:
        group.add_argument(
            setting.flag, dest=setting.name, type=_color, metavar="R,G,B[,A]", help=help_text + " (0..1 or #RRGGBB)"
        )
    else:
        group.add_argument(
            setting.flag,
            dest=setting.name,
            type=_finite_float,
            metavar=_METAVARS.get(setting.subtype, "X"),
            help=help_text,
        )


def build_parser(prog: str = "solidwire render") -> argparse.ArgumentParser:
    parser = _Parser(
        prog=prog,
        description="Render a .blend with the SolidWire engine.",
        epilog=f"From a shell: blender -c {EXTENSION_ID} render SCENE.blend [-o OUT.png] [-a | -f N] [options]",
    )
    parser.add_argument("blend", nargs="?", metavar="SCENE.blend", help="the .blend file to render")
    parser.add_argument(
        "-o",
        "--output",
        metavar="PATH",
        help="image file to write (.png, .jpg, .tif, .exr, .webp, .bmp); '#' characters become the frame "
        "number, '//' is the .blend's folder (default: the scene's output path and format)",
    )
    parser.add_argument("--scene", metavar="NAME", help="scene to render (default: the file's active scene)")
    parser.add_argument("--camera", metavar="NAME", help="camera object to render from (default: the scene camera)")

    frames = parser.add_argument_group("frames (as Blender's own command line spells them)")
    frames.add_argument(
        "-f",
        "--render-frame",
        dest="frame_list",
        type=_frame_list,
        metavar="N",
        help="render frame N ('A..B' and comma lists too; +N counts from the scene's start, "
        "-N from its end: -f -1 is the last frame)",
    )
    frames.add_argument(
        "-a",
        "--render-anim",
        dest="animation",
        action="store_true",
        help="render the scene's frame range with its frame step",
    )
    frames.add_argument(
        "-s",
        "--frame-start",
        type=_relative_frame,
        metavar="N",
        help="first frame of the range (implies -a; +N/-N relative to the scene's start)",
    )
    frames.add_argument(
        "-e",
        "--frame-end",
        type=_relative_frame,
        metavar="N",
        help="last frame of the range (implies -a; +N/-N relative to the scene's end)",
    )
    frames.add_argument("-j", "--frame-jump", type=_frame_step, metavar="N", help="frame step (implies -a)")
    frames.add_argument("--frames", type=_frame_range, metavar="A-B", help="frame or frame range (older spelling)")

    look = parser.add_argument_group("look (overrides the scene's SolidWire settings for this render)")
    look.add_argument("--preset", metavar="NAME|FILE", help="apply a preset (by name, or a .json file) first")
    for setting in schema.settings_in(schema.SCENE):
        if setting.flag:
            _add_setting_option(look, setting)
    for pair in schema.CLI_RANGES:
        look.add_argument(
            pair.flag,
            dest=pair.flag[2:].replace("-", "_"),
            type=_finite_float,
            nargs=2,
            metavar=pair.metavar,
            help=pair.help,
        )
        if pair.off_flag:
            look.add_argument(
                pair.off_flag,
                dest=pair.off_flag[2:].replace("-", "_"),
                action="store_true",
                help=f"switch {schema.BY_NAME[pair.enables].label.lower()} off",
            )

    image = parser.add_argument_group("image")
    film = image.add_mutually_exclusive_group()
    film.add_argument(
        "--transparent",
        dest="transparent",
        action="store_true",
        default=None,
        help="transparent film (alpha where nothing is drawn)",
    )
    film.add_argument("--opaque", dest="transparent", action="store_false", help="world colour behind the meshes")
    image.add_argument("--width", type=_positive_int, metavar="PX", help="resolution X")
    image.add_argument("--height", type=_positive_int, metavar="PX", help="resolution Y")
    image.add_argument("--percentage", type=_positive_int, metavar="PCT", help="resolution percentage")
    image.add_argument("--color-depth", choices=("8", "16"), help="bits per channel for PNG/TIFF (default 8)")

    image.add_argument(
        "--overwrite",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="replace frames that exist (default: the scene's Overwrite setting; with "
        "--no-overwrite an existing frame is skipped, as Blender skips it)",
    )

    report = parser.add_argument_group("progress")
    report.add_argument(
        "--progress",
        choices=("text", "json"),
        default="text",
        help="one line per frame for people (text) or one JSON object per frame (json)",
    )
    report.add_argument("--print-stats", action="store_true", help="print the frame statistics after each frame")

    over = parser.add_argument_group("wire over a render")
    over.add_argument(
        "--over",
        metavar="ENGINE",
        help="render the image underneath with ENGINE (CYCLES, BLENDER_EEVEE or EEVEE, "
        "BLENDER_WORKBENCH or WORKBENCH, SCENE = the file's engine) and write the "
        "SolidWire pass composited over it",
    )
    over.add_argument(
        "--over-samples",
        type=_positive_int,
        metavar="N",
        help="samples of the render underneath (Cycles, EEVEE; default: the scene's)",
    )
    over.add_argument(
        "--over-layers",
        action="store_true",
        help="also write the two float layers as NAME.beauty.exr and NAME.wire.exr",
    )
    return parser


# -- set-up --------------------------------------------------------------------


def check_blend_file(path: Path) -> None:
    if not path.exists():
        raise UsageError(f"'{path}' does not exist")
    if not path.is_file():
        raise UsageError(f"'{path}' is not a file")
    try:
        with path.open("rb") as handle:
            head = handle.read(8)
    except OSError as exc:
        raise UsageError(f"cannot read '{path}': {exc.strerror}") from None
    if not head.startswith(BLEND_MAGICS):
        raise UsageError(f"'{path}' is not a .blend file")


def open_blend(path: Path) -> None:
    check_blend_file(path)
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except RuntimeError as exc:
        raise UsageError(f"cannot open '{path}': {one_line(exc)}") from None


def load_scene(args, build_demo=None):
    """Open what is to be rendered and return its scene. ``build_demo``
    (scripts/render.py --demo) builds a scene instead of opening a file."""
    if build_demo is not None:
        if args.blend:
            raise UsageError("give either SCENE.blend or --demo, not both")
        return build_demo()
    if args.blend:
        open_blend(Path(args.blend).expanduser().resolve())
    elif not (bpy.app.binary_path and bpy.data.filepath):
        # Without SCENE.blend only a file Blender itself opened can be rendered.
        # (When Blender fails to open the file on its command line it carries
        # on with an unsaved default file; that must not be rendered instead.)
        raise UsageError("no scene given: pass SCENE.blend or --demo")
    if args.scene:
        scene = bpy.data.scenes.get(args.scene)
        if scene is None:
            names = ", ".join(s.name for s in bpy.data.scenes)
            raise UsageError(f"no scene named '{args.scene}' (scenes: {names})")
        return scene
    return bpy.context.scene


def _checked_rna(owner, name: str, value, option: str):
    """``value`` if it lies inside the property's hard range (Blender would
    otherwise clamp it silently)."""
    prop = owner.bl_rna.properties[name]
    if value < prop.hard_min or value > prop.hard_max:
        raise UsageError(f"{option} {value} is out of range [{prop.hard_min:g}, {prop.hard_max:g}]")
    return value


def _checked(setting: schema.Setting, value, option: str):
    try:
        return setting.check(value)
    except ValueError as exc:
        reason = str(exc).replace(f"'{setting.name}'", option, 1)
        raise UsageError(reason) from None


def apply_preset(settings, text: str) -> None:
    """``--preset NAME|FILE``: a preset file when the text names one, else a
    preset by name (built-in or the user's). A fade range the preset takes
    from the scene is measured from the scene camera (at the current frame)."""
    try:
        path = Path(text).expanduser()
        preset = presets.load(path) if text.endswith(".json") or path.is_file() else presets.find(text)
    except presets.PresetNotFound:
        # The names to choose from, so a typo in a farm job is fixed at once.
        names = [p.name for p in presets.all_presets()]
        raise UsageError(f"--preset: {presets.unknown_preset_message(text, names)}") from None
    except presets.PresetError as exc:
        raise UsageError(f"--preset: {exc}") from None
    presets.apply(preset, settings, depth_range=lambda: camera_fade_range(settings.id_data))


def apply_options(scene, args) -> None:
    settings = scene.solidwire
    # The camera first: a preset may measure its fade range from it.
    if args.camera:
        camera = bpy.data.objects.get(args.camera)
        if camera is None or camera.type != "CAMERA" or camera.name not in scene.objects:
            cameras = ", ".join(o.name for o in scene.objects if o.type == "CAMERA") or "none"
            raise UsageError(f"no camera named '{args.camera}' in scene '{scene.name}' (cameras: {cameras})")
        scene.camera = camera
    # Any object may be the scene camera in Blender (it renders from that
    # object's transform with default lens settings); only none is an error.
    if scene.camera is None:
        raise UsageError(f"scene '{scene.name}' has no camera (add one, or pass --camera NAME)")
    if args.preset is not None:
        apply_preset(settings, args.preset)
    # Schema order: diagonal_mode is set before pattern_duty (choosing a
    # pattern mode resets the duty to that mode's own).
    for setting in schema.settings_in(schema.SCENE):
        value = getattr(args, setting.name, None) if setting.flag else None
        if value is not None:
            setattr(settings, setting.name, _checked(setting, value, setting.flag))
    for pair in schema.CLI_RANGES:
        off = getattr(args, pair.off_flag[2:].replace("-", "_"), False) if pair.off_flag else False
        values = getattr(args, pair.flag[2:].replace("-", "_"))
        if values is not None and off:
            raise UsageError(f"give either {pair.flag} or {pair.off_flag}, not both")
        if values is not None:
            first, second = (
                _checked(schema.BY_NAME[name], value, f"{pair.flag} {metavar}")
                for name, value, metavar in zip(pair.names, values, pair.metavar)
            )
            if second <= first:
                raise UsageError(
                    f"{pair.flag}: {pair.metavar[1]} ({second:g}) must be beyond {pair.metavar[0]} ({first:g})"
                )
            setattr(settings, pair.names[0], first)
            setattr(settings, pair.names[1], second)
            if pair.enables:
                setattr(settings, pair.enables, True)
        if off:
            setattr(settings, pair.enables, False)

    render = scene.render
    if args.transparent is not None:
        render.film_transparent = args.transparent
    if args.width is not None:
        render.resolution_x = _checked_rna(render, "resolution_x", args.width, "--width")
    if args.height is not None:
        render.resolution_y = _checked_rna(render, "resolution_y", args.height, "--height")
    if args.percentage is not None:
        render.resolution_percentage = _checked_rna(render, "resolution_percentage", args.percentage, "--percentage")


def frames_to_render(scene, args) -> list[int]:
    """The frames, by Blender's rules: -f wins, -a (or -s/-e/-j) renders the
    range with its step, otherwise the current frame. Relative numbers count
    as Blender's command line counts them (-f: +N from the start, -N from the
    end; -s and -e: from the scene's own start and end), and every frame is
    clamped to Blender's frame limits."""
    ranged = args.animation or args.frame_start is not None or args.frame_end is not None or args.frame_jump
    given = [flag for flag, on in (("-f", args.frame_list), ("--frames", args.frames), ("-a/-s/-e/-j", ranged)) if on]
    if len(given) > 1:
        raise UsageError(f"give only one of {', '.join(given)}")
    if args.frame_list:
        frames = []
        for first, last in args.frame_list:
            start = first.resolve(scene.frame_start, scene.frame_end)
            end = last.resolve(scene.frame_start, scene.frame_end)
            if end < start:
                raise UsageError(f"-f: the frame range {start}..{end} ends before it starts")
            frames.extend(range(start, end + 1))
        return list(dict.fromkeys(frames))
    if args.frames:
        first, last = args.frames
        return list(range(max(first, MIN_FRAME), min(last, MAX_FRAME) + 1))
    if ranged:
        start, end = scene.frame_start, scene.frame_end
        if args.frame_start is not None:
            start = args.frame_start.resolve(scene.frame_start, scene.frame_start - 1)
        if args.frame_end is not None:
            end = args.frame_end.resolve(scene.frame_end, scene.frame_end - 1)
        step = max(args.frame_jump or scene.frame_step, 1)  # a saved step of 0 renders every frame
        if end < start:
            raise UsageError(f"the frame range {start}..{end} ends before it starts")
        return list(range(start, end + 1, step))
    return [scene.frame_current]


# -- output --------------------------------------------------------------------


def output_template(text: str) -> Path:
    """The -o path made absolute ('//' means next to the .blend, as in Blender)."""
    if text.startswith("//"):
        if not bpy.data.filepath:
            raise UsageError(f"-o '{text}' is relative to the .blend, but no .blend is open")
        text = bpy.path.abspath(text)
    return Path(text).expanduser().absolute()


def frame_number(frame: int, digits: int) -> str:
    """The frame as Blender writes it into a name (C's "%.*d"): at least
    ``digits`` digits, a minus sign in front of them: -3 with '####' is
    '-0003'."""
    return ("-" if frame < 0 else "") + str(abs(frame)).zfill(digits)


def frame_path(template: Path, frame: int, frame_count: int) -> Path:
    """Blender's rule for -o: the last run of '#' becomes the zero-padded
    frame number. A range rendered to a name without '#' gets 4 digits
    appended to the name (before the extension), so frames never overwrite
    each other."""
    name = template.name
    runs = list(re.finditer(r"#+", name))
    if runs:
        run = runs[-1]
        number = frame_number(frame, len(run.group()))
        return template.with_name(name[: run.start()] + number + name[run.end() :])
    if frame_count > 1:
        return template.with_name(f"{template.stem}{frame_number(frame, 4)}{template.suffix}")
    return template


def scene_frame_path(scene, frame: int) -> Path:
    """Without -o: the scene's output path exactly as Blender fills it in
    (frame number, '//', the format's extension)."""
    if not scene.render.filepath:
        raise UsageError(f"scene '{scene.name}' has no output path: pass -o PATH")
    if scene.render.filepath.startswith("//") and not bpy.data.filepath:
        raise UsageError("the scene's output path is relative to the .blend, but no .blend is open: pass -o PATH")
    return Path(bpy.path.abspath(scene.render.frame_path(frame=frame))).absolute()


def check_output_folder(directory: Path) -> None:
    """Prove the folder writable, or creatable, before any slow work; it is
    created only when the first frame is written (a failed run leaves none)."""
    try:
        output.check_output_folder(directory, create=False)
    except output.OutputError as exc:
        raise UsageError(str(exc)) from None


def check_output(path: Path) -> None:
    """Fail before rendering if the image cannot be written there."""
    if path.is_dir():
        raise UsageError(f"output '{path}' is a directory")
    if path.exists() and not os.access(path, os.W_OK):
        raise UsageError(f"cannot overwrite '{path}': permission denied")


def file_format_of(path: Path, color_depth: str | None) -> str:
    file_format = FILE_FORMATS.get(path.suffix.lower())
    if file_format is None:
        known = ", ".join(sorted(FILE_FORMATS))
        raise UsageError(f"unknown image type '{path.suffix or path.name}' (use one of {known})")
    if color_depth is not None and file_format not in ("PNG", "TIFF"):
        raise UsageError(f"--color-depth applies to PNG and TIFF only, not '{path.suffix}'")
    return file_format


MULTILAYER = "OPEN_EXR_MULTILAYER"
VIDEO_FORMATS = ("FFMPEG", "AVI_JPEG", "AVI_RAW")


# Pass switches that are options of another pass, not passes of their own.
_NOT_PASSES = {"use_pass_combined", "use_pass_cryptomatte_accurate"}


def written_passes(scene) -> list[str]:
    """The passes beyond Combined that a multilayer file of the scene holds
    (the view layers' own and SolidWire's), by their names in Blender's UI."""
    names = []
    for layer in scene.view_layers:
        if not layer.use:
            continue
        owners = [layer] + [getattr(layer, "solidwire", None)]
        for owner in owners:
            if owner is None:
                continue
            for prop in owner.bl_rna.properties:
                name = prop.identifier
                if (
                    name.startswith("use_pass_")
                    and name not in _NOT_PASSES
                    and prop.type == "BOOLEAN"
                    and getattr(owner, name)
                ):
                    names.append(prop.name)
    return list(dict.fromkeys(names))


def _is_multilayer(scene) -> bool:
    return scene.render.image_settings.file_format == MULTILAYER


def set_file_format(scene, path: Path, color_depth: str | None, *, over: bool = False) -> str:
    """Set the output format from -o's extension; returns a one-line note when
    the scene's multilayer passes are not written ("" otherwise).

    ``.exr`` keeps a multilayer scene multilayer (every pass the scene would
    write), unless the image is a composite (--over), which is one image."""
    file_format = file_format_of(path, color_depth)
    image = scene.render.image_settings
    multilayer = _is_multilayer(scene)
    passes = written_passes(scene) if multilayer else []
    if file_format == "OPEN_EXR" and multilayer and not over:
        # The scene's own multilayer settings (depth, codec) stay as they are.
        scene.render.use_file_extension = False
        return ""
    compat.set_media_type(image, "IMAGE")
    image.file_format = file_format
    image.color_mode = "RGBA" if file_format in FORMATS_WITH_ALPHA else "RGB"
    if file_format in ("PNG", "TIFF"):
        image.color_depth = color_depth or "8"
    # The path given is the path written: no extension added by Blender.
    scene.render.use_file_extension = False
    if not passes:
        return ""
    what = "the --over composite is one image" if over else f"'{path.suffix}' holds one image"
    keep = "" if over else "; -o NAME.exr keeps them"
    return f"note: {what}: the scene's passes {', '.join(passes)} are not written{keep}"


def check_scene_format(scene, over: bool) -> None:
    """Without -o the scene's format is written: refuse, before rendering, a
    format the command line cannot write."""
    file_format = scene.render.image_settings.file_format
    if file_format in VIDEO_FORMATS or getattr(scene.render.image_settings, "media_type", "") == "VIDEO":
        raise UsageError(
            f"the scene's output format is a video ({file_format}); the command line writes one image "
            "per frame: pass -o NAME_####.png (or .exr, .tif, ...)"
        )
    if over and file_format == MULTILAYER:
        raise UsageError(
            "--over writes one composited image, but the scene's output format is multilayer "
            "OpenEXR: pass -o NAME_####.exr (single-layer) or another image type"
        )


# -- rendering -----------------------------------------------------------------


def _seconds(value: float) -> str:
    return f"{value:.2f} s"


def over_renderer(scene, args):
    """With --over: a function (scene, path) that renders the wire over the
    chosen engine's render; the engine is checked now (exit 2 if unknown)."""
    if args.over is None:
        if args.over_samples is not None or args.over_layers:
            raise UsageError("--over-samples and --over-layers need --over ENGINE")
        return None
    try:
        engine = composite.resolve_engine(scene, args.over)
        composite.check_output_format(scene)
    except composite.CompositeError as exc:
        raise UsageError(f"--over: {exc}") from None

    def render(scene, path, final_path):
        try:
            composite.render_wire_over(
                scene, path, engine, keep_layers=args.over_layers, layers_name=final_path, samples=args.over_samples
            )
        except composite.CompositeError as exc:
            raise RenderFailed(f"--over {engine}: {exc}") from None

    return render


class Interrupted(Exception):
    """SIGINT or SIGTERM ended the run (exit code 128 + the signal)."""

    def __init__(self, signum: int, done: int, total: int):
        super().__init__(signum)
        self.signum, self.done, self.total = signum, done, total


def _signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class Interrupts:
    """SIGINT (Ctrl+C) and SIGTERM (a farm cancelling a task) while frames
    are rendered.

    The first signal lets the frame in progress finish and be written, then
    the run stops (exit 128 + the signal: 130, 143). No KeyboardInterrupt is
    raised: Blender would print it from whatever handler it lands in and
    carry on. A second signal stops at once, after removing the frame's
    temporary file (and its placeholder). Python runs signal handlers only
    between bytecodes of the main thread, which a long render by another
    engine (--over) does not reach for minutes; so the signal is read from a
    wake-up pipe by a small thread, which sees it immediately."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self):
        self.signum: int | None = None
        self.discard: set = set()  # removed when the process stops at once
        self.folders: list = []  # created by this run: removed if left empty
        self._previous: dict = {}
        self._pipe: tuple | None = None
        self._previous_fd = -1
        self._watcher: threading.Thread | None = None

    def install(self) -> bool:
        if threading.current_thread() is not threading.main_thread():
            return False  # signal handlers can only be set from the main thread
        try:
            read_fd, write_fd = os.pipe()
        except OSError:
            read_fd = write_fd = None
        try:
            if write_fd is not None:
                os.set_blocking(write_fd, False)
                # Windows refuses a pipe here (ValueError): then the handlers
                # below do the work, when the main thread runs Python.
                self._previous_fd = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
                self._pipe = (read_fd, write_fd)
        except (AttributeError, ValueError, OSError):
            os.close(read_fd)
            os.close(write_fd)
        self._previous = {sig: signal.signal(sig, self._on_signal) for sig in self.SIGNALS}
        if self._pipe is not None:
            self._watcher = threading.Thread(
                target=self._watch, args=(self._pipe[0],), name="solidwire-signals", daemon=True
            )
            self._watcher.start()
        return True

    def uninstall(self) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler if handler is not None else signal.SIG_DFL)
        self._previous = {}
        if self._pipe is None:
            return
        signal.set_wakeup_fd(self._previous_fd)
        read_fd, write_fd = self._pipe
        self._pipe = None
        os.close(write_fd)  # ends the watcher's read
        # The watcher is gone before the run returns: a thread still alive at
        # interpreter exit keeps the bpy 4.5 module from shutting Blender down,
        # and the process then hangs in a static destructor (Blender's audio
        # thread is never stopped).
        if self._watcher is not None:
            self._watcher.join(timeout=5.0)
            self._watcher = None
        os.close(read_fd)

    def _on_signal(self, signum, frame):
        if self._pipe is None:  # no watcher thread: handled here, later
            self._received(signum)

    def _watch(self, read_fd: int) -> None:
        while True:
            try:
                data = os.read(read_fd, 1)
            except OSError:
                return
            if not data:
                return
            if data[0] in self.SIGNALS:
                self._received(data[0])

    def _received(self, signum: int) -> None:
        if self.signum is None:
            self.signum = signum
        else:
            self.stop_now(signum)

    def check(self, done: int, total: int) -> None:
        if self.signum is not None:
            raise Interrupted(self.signum, done, total)

    def remove_leftovers(self) -> None:
        for path in list(self.discard):
            try:
                if path.name.endswith(TEMP_SUFFIX) or (path.is_file() and path.stat().st_size == 0):
                    path.unlink()
            except OSError:
                pass
        self.discard.clear()
        for folder in reversed(self.folders):
            try:
                folder.rmdir()  # only when empty
            except OSError:
                pass

    def stop_now(self, signum: int) -> None:
        self.remove_leftovers()
        try:
            print(
                f"solidwire: stopped by {_signal_name(signum)} during a frame; frames already written are complete",
                file=sys.stderr,
                flush=True,
            )
        finally:
            os._exit(128 + signum)


_interrupts = Interrupts()

# Frames are rendered to ".<name>.solidwire-<pid>.tmp" in the frame's folder
# and renamed when complete: a file under a frame's name is always whole. The
# temporary name ends in no image extension, so nothing watching the folder
# (a farm's preview, a compositor reading a sequence) takes it for a frame.
TEMP_SUFFIX = ".solidwire-tmp"


def blender_path(path: Path) -> str:
    """``path`` as Blender must read it to write exactly there: from 4.5
    (path templates) Blender reads "{name}" in an output path as a template
    variable (and fails on unknown ones), so literal braces are doubled."""
    text = str(path)
    if bpy.app.version >= (4, 5, 0):
        text = text.replace("{", "{{").replace("}", "}}")
    return text


def temporary_path(path: Path) -> Path:
    return path.with_name(f".{path.name}.{os.getpid()}{TEMP_SUFFIX}")


def ensure_folder(directory: Path) -> None:
    """Create ``directory`` (and its parents) when the first frame is written,
    remembering what was created so a failed run can leave nothing behind."""
    missing = []
    folder = directory
    while not folder.exists():
        missing.append(folder)
        folder = folder.parent
    for folder in reversed(missing):
        try:
            folder.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            raise RenderFailed(f"cannot create output folder '{folder}': {exc.strerror}") from None
        _interrupts.folders.append(folder)


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except FileNotFoundError:
        pass


def write_frame(scene, frame: int, path: Path, over, *, placeholder: bool) -> None:
    """Render ``frame`` and put it at ``path`` whole: rendered to a temporary
    name in the same folder, then renamed (os.replace, atomic on one file
    system). With a placeholder (render.use_placeholder) an empty file holds
    the frame's name while it renders, as Blender does, and is removed again
    if the frame is not finished."""
    ensure_folder(path.parent)
    placed = False
    if placeholder and not path.exists():
        try:
            path.touch(exist_ok=False)
            placed = True
            _interrupts.discard.add(path)
        except FileExistsError:
            pass  # another machine's placeholder: its frame now
        except OSError as exc:
            raise RenderFailed(f"frame {frame}: cannot write placeholder '{path}': {exc.strerror}") from None
    tmp = temporary_path(path)
    _interrupts.discard.add(tmp)
    try:
        scene.render.filepath = blender_path(tmp)
        try:
            if over is None:
                bpy.ops.render.render(write_still=True, scene=scene.name)
            else:
                over(scene, tmp, path)
        except RuntimeError as exc:
            raise RenderFailed(f"frame {frame}: {one_line(exc)}") from None
        try:
            size = tmp.stat().st_size
        except FileNotFoundError:
            size = 0
        if size == 0:
            raise RenderFailed(f"frame {frame}: no image was written to '{path}'")
        try:
            os.replace(tmp, path)
        except OSError as exc:
            raise RenderFailed(f"frame {frame}: cannot write '{path}': {exc.strerror}") from None
    except BaseException:
        _remove(tmp)
        if placed and path.is_file() and path.stat().st_size == 0:
            _remove(path)
        raise
    finally:
        _interrupts.discard.discard(tmp)
        _interrupts.discard.discard(path)


class Progress:
    """One progress line (or JSON object) per frame, and Blender's own
    ``Saved:`` line under the frame's final name (Blender's line names the
    temporary file): render farms read it, e.g. Flamenco's Worker for its
    preview of the latest frame."""

    def __init__(self, scene, args, frames: list[int]):
        self.scene, self.args = scene, args
        self.position = {frame: index for index, frame in enumerate(frames, start=1)}
        self.count = len(frames)
        self.done: set = set()
        self.start_all = time.perf_counter()

    def written(self, frame: int, path: Path, seconds: float) -> None:
        self.done.add(frame)
        index, count = self.position[frame], self.count
        print(f"Saved: '{path}'", flush=True)
        elapsed = time.perf_counter() - self.start_all
        eta = elapsed / len(self.done) * (count - len(self.done))
        stats = runtime.stats()
        if self.args.progress == "json":
            record = {
                "frame": frame,
                "index": index,
                "count": count,
                "seconds": round(seconds, 4),
                "eta_seconds": round(eta, 3),
                "output": str(path),
                "stats": stats,
            }
            print(json.dumps(record), flush=True)
            return
        width, height = _render_size(self.scene)
        if count == 1:
            print(f"solidwire: rendered {path} ({width}x{height}) in {_seconds(seconds)}", flush=True)
        else:
            print(
                f"solidwire: frame {index} of {count} (frame {frame}, {width}x{height}) "
                f"in {_seconds(seconds)} -> {path}; elapsed {_seconds(elapsed)}, ETA {_seconds(eta)}",
                flush=True,
            )
        if self.args.print_stats:
            print("solidwire: stats " + ", ".join(f"{k}={_format_stat(v)}" for k, v in stats.items()), flush=True)

    def skipped(self, frame: int, path: Path) -> None:
        self.done.add(frame)
        _report_skipped(self.args, frame, self.position[frame], self.count, path)


# Frames at most this far apart are drawn by one animation render (Blender
# evaluates the frames in between without drawing them, as its own
# -a does with a frame step); farther apart, a render each is cheaper.
MAX_RUN_STEP = 8


def animation_runs(frames: list[int]) -> list[list[int]]:
    """The frames split into runs of a constant step (at most MAX_RUN_STEP)
    that one Blender animation render can draw, in the order given."""
    runs: list[list[int]] = []
    for frame in frames:
        run = runs[-1] if runs else None
        if run and 0 < frame - run[-1] <= MAX_RUN_STEP and (len(run) == 1 or frame - run[-1] == run[1] - run[0]):
            run.append(frame)
        else:
            runs.append([frame])
    return runs


def render_frames(scene, paths: dict, args, over=None, *, overwrite: bool = True, placeholder: bool = False) -> None:
    """Render each frame to its path, with one progress line (or JSON
    object) per frame. An existing frame is skipped when overwriting is off,
    as Blender skips it (so a requeued job renders only what is missing).

    Runs of frames are drawn by Blender's own animation render, which keeps
    one render depsgraph from frame to frame, where a render per frame builds
    a new one each time. A render per frame is used where Blender must decide
    just before each frame (overwrite off, placeholders: other machines may
    be rendering the same frames), for --over, and for negative frames (the
    scene's range cannot start below 0)."""
    for folder in dict.fromkeys(path.parent for path in paths.values()):
        check_output_folder(folder)
    for path in dict.fromkeys(paths.values()):
        check_output(path)
    frames = list(paths)
    progress = Progress(scene, args, frames)
    per_frame = over is not None or not overwrite or placeholder
    runs = [[frame] for frame in frames] if per_frame else animation_runs(frames)
    for run in runs:
        _interrupts.check(len(progress.done), len(frames))
        if len(run) > 1 and run[0] >= 0 and len({paths[frame].parent for frame in run}) == 1:
            render_animation(scene, run, paths, progress)
            continue
        for frame in run:
            _interrupts.check(len(progress.done), len(frames))
            path = paths[frame]
            if not overwrite and path.exists():
                progress.skipped(frame, path)
                continue
            scene.frame_set(frame)
            start = time.perf_counter()
            write_frame(scene, frame, path, over, placeholder=placeholder)
            progress.written(frame, path, time.perf_counter() - start)
    _interrupts.check(len(frames), len(frames))


def render_animation(scene, run: list[int], paths: dict, progress: Progress) -> None:
    """Draw ``run`` (frames of one step, one folder) with Blender's animation
    render. Blender writes each frame to a temporary name in the frame's
    folder; the render_write handler (called once the file is complete)
    renames it into place and reports it. A stop request or a failed rename
    ends the render before the next frame (see runtime.render_stop_reason)."""
    folder = paths[run[0]].parent
    ensure_folder(folder)
    render = scene.render
    render.filepath = blender_path(folder / f".frame.{'#' * 7}.{os.getpid()}{TEMP_SUFFIX}")
    render.use_file_extension = False
    # The temporary names never exist, and the overwrite rules were applied
    # before choosing this path.
    render.use_overwrite, render.use_placeholder = True, False
    scene.use_preview_range = False  # the range below is the one rendered
    scene.frame_end = MAX_FRAME  # so the start may move past the old end
    scene.frame_start, scene.frame_end = run[0], run[-1]
    scene.frame_step = run[1] - run[0]
    failure: list[str] = []
    started = {"frame": run[0], "time": time.perf_counter()}

    def temporary(frame: int) -> Path:
        return Path(bpy.path.abspath(render.frame_path(frame=frame)))

    def on_pre(scene_arg, *_args):
        if scene_arg.name != scene.name:
            return
        started["frame"], started["time"] = scene.frame_current, time.perf_counter()
        _interrupts.discard.add(temporary(scene.frame_current))

    def on_write(scene_arg, *_args):
        if scene_arg.name != scene.name:
            return
        frame = scene.frame_current
        tmp = temporary(frame)
        try:
            path = paths[frame]
            if tmp.stat().st_size == 0:
                raise OSError("the image is empty")
            os.replace(tmp, path)
            _interrupts.discard.discard(tmp)
            progress.written(frame, path, time.perf_counter() - started["time"])
        except Exception as exc:  # noqa: BLE001 - a handler must not raise: Blender would print it and go on
            failure.append(
                f"frame {frame}: cannot write '{paths.get(frame, tmp)}': {getattr(exc, 'strerror', None) or exc}"
            )

    def stop_reason():
        if _interrupts.signum is not None:
            return f"stopped by {_signal_name(_interrupts.signum)}"
        return "stopped after an error" if failure else None

    handlers = bpy.app.handlers
    handlers.render_pre.append(on_pre)
    handlers.render_write.append(on_write)
    runtime.render_stop_reason = stop_reason
    try:
        bpy.ops.render.render(animation=True, scene=scene.name)
    except RuntimeError as exc:
        if _interrupts.signum is not None:
            raise Interrupted(_interrupts.signum, len(progress.done), progress.count) from None
        if failure:
            raise RenderFailed(failure[0]) from None
        raise RenderFailed(f"frame {started['frame']}: {one_line(exc)}") from None
    finally:
        runtime.render_stop_reason = None
        handlers.render_pre.remove(on_pre)
        handlers.render_write.remove(on_write)
        leftover = temporary(started["frame"])
        _interrupts.discard.discard(leftover)
        if leftover.exists():
            _remove(leftover)
    if failure:
        raise RenderFailed(failure[0])
    missing = [frame for frame in run if frame not in progress.done]
    if missing:
        raise RenderFailed(f"frame {missing[0]}: no image was written to '{paths[missing[0]]}'")


def _report_skipped(args, frame: int, index: int, count: int, path: Path) -> None:
    # Blender's line for a skipped frame, which render farms count as progress.
    print(f'skipping existing frame "{path}"', flush=True)
    if args.progress == "json":
        print(
            json.dumps({"frame": frame, "index": index, "count": count, "skipped": True, "output": str(path)}),
            flush=True,
        )
    else:
        print(
            f"solidwire: frame {index} of {count} (frame {frame}) skipped: '{path}' exists and overwriting is off",
            flush=True,
        )


def _format_stat(value) -> str:
    return f"{value:.2f}" if isinstance(value, float) else str(value)


def _render_size(scene) -> tuple[int, int]:
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(int(r.resolution_x * scale), 1), max(int(r.resolution_y * scale), 1)


def run(arguments: list[str], *, prog: str = "solidwire render", build_demo=None) -> int:
    """Parse ``arguments`` and render. Raises UsageError / RenderFailed."""
    args = build_parser(prog).parse_args(_join_signed_values(arguments))
    if build_demo is None and not args.blend and not bpy.app.binary_path:
        raise UsageError("no scene given: pass SCENE.blend or --demo")
    if args.output is not None:
        file_format_of(Path(args.output), args.color_depth)  # before any slow work
        if not args.output.startswith("//"):
            # Fail before the (possibly slow) file load when the folder is unusable.
            check_output_folder(output_template(args.output).parent)
    scene = load_scene(args, build_demo)
    apply_options(scene, args)
    frames = frames_to_render(scene, args)
    over = args.over is not None
    if args.output is not None:
        template = output_template(args.output)  # '//' resolves against the file just opened
        note = set_file_format(scene, template, args.color_depth, over=over)
        paths = {frame: frame_path(template, frame, len(frames)) for frame in frames}
    else:
        if args.color_depth is not None:
            raise UsageError("--color-depth needs -o (without it the scene's own format is used)")
        check_scene_format(scene, over)
        note = ""
        paths = {frame: scene_frame_path(scene, frame) for frame in frames}
        # frame_path() already holds the extension: Blender must not add another.
        scene.render.use_file_extension = False
    if scene.render.use_multiview and scene.render.image_settings.views_format == "INDIVIDUAL":
        # Blender then writes one file per view (NAME_L, NAME_R), not the
        # frame's one file, which the command line writes and renames.
        raise UsageError(
            f"scene '{scene.name}' renders stereo views to separate files, which the command line "
            "does not write: choose Stereo 3D in the output's Views Format, or render with "
            "blender -b SCENE.blend -E SOLIDWIRE -a"
        )
    renderer = over_renderer(scene, args)  # before the engine is set: --over SCENE
    # Blender's own rules for an existing frame: skipped unless overwriting
    # (render.use_overwrite, or --overwrite / --no-overwrite for this run);
    # an empty placeholder file while a frame renders (render.use_placeholder).
    overwrite = scene.render.use_overwrite if args.overwrite is None else args.overwrite
    placeholder = scene.render.use_placeholder
    if note:
        print(f"solidwire: {note}", file=sys.stderr, flush=True)
    scene.render.engine = ENGINE_ID
    render_frames(scene, paths, args, renderer, overwrite=overwrite, placeholder=placeholder)
    return 0


def main(arguments: list[str], **kwargs) -> int:
    """Run the command line; return the exit code (never raises)."""
    global _interrupts
    _interrupts = Interrupts()
    _interrupts.install()
    ok = False
    try:
        code = run(arguments, **kwargs)
        ok = True
        return code
    except UsageError as exc:
        print(f"solidwire: error: {exc}", file=sys.stderr, flush=True)
        return EXIT_USAGE
    except Interrupted as exc:
        print(
            f"solidwire: stopped by {_signal_name(exc.signum)} after {exc.done} of {exc.total} frames; "
            "frames already written are complete",
            file=sys.stderr,
            flush=True,
        )
        return 128 + exc.signum
    except KeyboardInterrupt:  # only where no handler could be installed
        print("solidwire: stopped by SIGINT", file=sys.stderr, flush=True)
        return 128 + signal.SIGINT
    except RenderFailed as exc:
        print(f"solidwire: error: render failed: {exc}", file=sys.stderr, flush=True)
        return EXIT_FAILURE
    except Exception:  # noqa: BLE001  (a bug: keep the traceback, but never exit 0)
        traceback.print_exc()
        print("solidwire: error: unexpected failure (traceback above)", file=sys.stderr, flush=True)
        return EXIT_FAILURE
    finally:
        if not ok:
            _interrupts.remove_leftovers()  # folders this run created, if still empty
        _interrupts.uninstall()


# -- `blender -c solidwire ...` ------------------------------------------------

_COMMANDS = {"render": "render a .blend with SolidWire (see: blender -c solidwire render --help)"}


def command(argv: list[str]) -> int:
    """The ``blender -c solidwire`` entry point: ``argv`` holds the words
    after the command name."""
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(f"usage: blender -c {EXTENSION_ID} <command> [options]\n\ncommands:")
        for name, text in _COMMANDS.items():
            print(f"  {name:10s}{text}")
        return 0 if argv else EXIT_USAGE
    if argv[0] != "render":
        print(f"solidwire: error: unknown command '{argv[0]}' (commands: {', '.join(_COMMANDS)})", file=sys.stderr)
        return EXIT_USAGE
    return main(argv[1:], prog=f"blender -c {EXTENSION_ID} render")


_cli_handle = None


def register_command() -> None:
    """Offer ``blender -c solidwire`` (Blender 4.2+ has register_cli_command)."""
    global _cli_handle
    register = getattr(bpy.utils, "register_cli_command", None)
    if register is not None and _cli_handle is None:
        _cli_handle = register(EXTENSION_ID, command)


def unregister_command() -> None:
    global _cli_handle
    if _cli_handle is not None:
        bpy.utils.unregister_cli_command(_cli_handle)
        _cli_handle = None
