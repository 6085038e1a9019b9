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
exit code 2; a failed render exits with code 1.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import time
import traceback
from pathlib import Path

import bpy

from ..core import compat, output, schema
from ..core.ids import ENGINE_ID, EXTENSION_ID
from ..core.log import one_line
from . import composite, ops, presets, runtime

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


def _frame_list(text: str) -> list[int]:
    """Blender's -f syntax: 'N', 'A..B', or a comma list of those."""
    frames: list[int] = []
    for part in text.split(","):
        match = re.fullmatch(r"\s*(-?\d+)\s*(?:\.\.\s*(-?\d+)\s*)?", part)
        if not match:
            raise argparse.ArgumentTypeError(f"'{text}' is not a frame list (N, A..B, or a comma list)")
        first = int(match.group(1))
        last = int(match.group(2)) if match.group(2) is not None else first
        if last < first:
            raise argparse.ArgumentTypeError(f"frame range '{part.strip()}' ends before it starts")
        frames.extend(range(first, last + 1))
    return frames


def _add_setting_option(group, setting: schema.Setting) -> None:
    """The option of one schema setting (its flag, parser and help)."""
    help_text = setting.description[0].lower() + setting.description[1:]
    if setting.kind == schema.BOOL:
        group.add_argument(setting.flag, dest=setting.name, action=argparse.BooleanOptionalAction,
                           default=None, help=help_text)
    elif setting.kind == schema.ENUM:
        # Upper-case identifiers take any case; names (matcaps) as written.
        upper = all(choice == choice.upper() for choice in setting.choices)
        group.add_argument(setting.flag, dest=setting.name, choices=setting.choices,
                           type=str.upper if upper else str, help=help_text)
    elif setting.kind == schema.COLOR:
        group.add_argument(setting.flag, dest=setting.name, type=_color, metavar="R,G,B[,A]",
                           help=help_text + " (0..1 or #RRGGBB)")
    else:
        group.add_argument(setting.flag, dest=setting.name, type=_finite_float,
                           metavar=_METAVARS.get(setting.subtype, "X"), help=help_text)


def build_parser(prog: str = "solidwire render") -> argparse.ArgumentParser:
    parser = _Parser(
        prog=prog,
        description="Render a .blend with the SolidWire engine.",
        epilog=f"From a shell: blender -c {EXTENSION_ID} render SCENE.blend [-o OUT.png] [-a | -f N] [options]",
    )
    parser.add_argument("blend", nargs="?", metavar="SCENE.blend", help="the .blend file to render")
    parser.add_argument(
        "-o", "--output", metavar="PATH",
        help="image file to write (.png, .jpg, .tif, .exr, .webp, .bmp); '#' characters become the frame "
             "number, '//' is the .blend's folder (default: the scene's output path and format)",
    )
    parser.add_argument("--scene", metavar="NAME", help="scene to render (default: the file's active scene)")
    parser.add_argument("--camera", metavar="NAME", help="camera object to render from (default: the scene camera)")

    frames = parser.add_argument_group("frames (as Blender's own command line spells them)")
    frames.add_argument("-f", "--render-frame", dest="frame_list", type=_frame_list, metavar="N",
                        help="render frame N ('A..B' and comma lists too)")
    frames.add_argument("-a", "--render-anim", dest="animation", action="store_true",
                        help="render the scene's frame range with its frame step")
    frames.add_argument("-s", "--frame-start", type=int, metavar="N", help="first frame of the range (implies -a)")
    frames.add_argument("-e", "--frame-end", type=int, metavar="N", help="last frame of the range (implies -a)")
    frames.add_argument("-j", "--frame-jump", type=_positive_int, metavar="N", help="frame step (implies -a)")
    frames.add_argument("--frames", type=_frame_range, metavar="A-B", help="frame or frame range (older spelling)")

    look = parser.add_argument_group("look (overrides the scene's SolidWire settings for this render)")
    look.add_argument("--preset", metavar="NAME|FILE", help="apply a preset (by name, or a .json file) first")
    for setting in schema.settings_in(schema.SCENE):
        if setting.flag:
            _add_setting_option(look, setting)
    for pair in schema.CLI_RANGES:
        look.add_argument(pair.flag, dest=pair.flag[2:].replace("-", "_"), type=_finite_float, nargs=2,
                          metavar=pair.metavar, help=pair.help)
        if pair.off_flag:
            look.add_argument(pair.off_flag, dest=pair.off_flag[2:].replace("-", "_"), action="store_true",
                              help=f"switch {schema.BY_NAME[pair.enables].label.lower()} off")

    image = parser.add_argument_group("image")
    film = image.add_mutually_exclusive_group()
    film.add_argument("--transparent", dest="transparent", action="store_true", default=None,
                      help="transparent film (alpha where nothing is drawn)")
    film.add_argument("--opaque", dest="transparent", action="store_false", help="world colour behind the meshes")
    image.add_argument("--width", type=_positive_int, metavar="PX", help="resolution X")
    image.add_argument("--height", type=_positive_int, metavar="PX", help="resolution Y")
    image.add_argument("--percentage", type=_positive_int, metavar="PCT", help="resolution percentage")
    image.add_argument("--color-depth", choices=("8", "16"), help="bits per channel for PNG/TIFF (default 8)")

    report = parser.add_argument_group("progress")
    report.add_argument("--progress", choices=("text", "json"), default="text",
                        help="one line per frame for people (text) or one JSON object per frame (json)")
    report.add_argument("--print-stats", action="store_true", help="print the frame statistics after each frame")

    over = parser.add_argument_group("wire over a render")
    over.add_argument("--over", metavar="ENGINE",
                      help="render the image underneath with ENGINE (CYCLES, BLENDER_EEVEE or EEVEE, "
                           "BLENDER_WORKBENCH or WORKBENCH, SCENE = the file's engine) and write the "
                           "SolidWire pass composited over it")
    over.add_argument("--over-samples", type=_positive_int, metavar="N",
                      help="samples of the render underneath (Cycles, EEVEE; default: the scene's)")
    over.add_argument("--over-layers", action="store_true",
                      help="also write the two float layers as NAME.beauty.exr and NAME.wire.exr")
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
    except presets.PresetError as exc:
        raise UsageError(f"--preset: {exc}") from None
    presets.apply(preset, settings, depth_range=lambda: ops.camera_fade_range(settings.id_data))


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
                raise UsageError(f"{pair.flag}: {pair.metavar[1]} ({second:g}) must be beyond {pair.metavar[0]} ({first:g})")
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
    range with its step, otherwise the current frame."""
    ranged = args.animation or args.frame_start is not None or args.frame_end is not None or args.frame_jump
    given = [flag for flag, on in (("-f", args.frame_list), ("--frames", args.frames), ("-a/-s/-e/-j", ranged)) if on]
    if len(given) > 1:
        raise UsageError(f"give only one of {', '.join(given)}")
    if args.frame_list:
        return list(dict.fromkeys(args.frame_list))
    if args.frames:
        first, last = args.frames
        return list(range(first, last + 1))
    if ranged:
        start = scene.frame_start if args.frame_start is None else args.frame_start
        end = scene.frame_end if args.frame_end is None else args.frame_end
        step = args.frame_jump or scene.frame_step
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


def frame_path(template: Path, frame: int, frame_count: int) -> Path:
    """Blender's rule for -o: the last run of '#' becomes the zero-padded
    frame number. A range rendered to a name without '#' gets 4 digits
    appended to the name (before the extension), so frames never overwrite
    each other."""
    name = template.name
    runs = list(re.finditer(r"#+", name))
    if runs:
        run = runs[-1]
        number = f"{frame:0{len(run.group())}d}" if frame >= 0 else f"-{-frame:0{len(run.group()) - 1}d}"
        return template.with_name(name[: run.start()] + number + name[run.end() :])
    if frame_count > 1:
        return template.with_name(f"{template.stem}{frame:04d}{template.suffix}")
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
    """Create the folder if needed (as Blender does) and prove it writable."""
    try:
        output.check_output_folder(directory)
    except output.OutputError as exc:
        raise UsageError(str(exc)) from None


def check_output(path: Path) -> None:
    """Fail before rendering if the image cannot be written there."""
    try:
        output.check_output(path)
    except output.OutputError as exc:
        raise UsageError(str(exc)) from None


def file_format_of(path: Path, color_depth: str | None) -> str:
    file_format = FILE_FORMATS.get(path.suffix.lower())
    if file_format is None:
        known = ", ".join(sorted(FILE_FORMATS))
        raise UsageError(f"unknown image type '{path.suffix or path.name}' (use one of {known})")
    if color_depth is not None and file_format not in ("PNG", "TIFF"):
        raise UsageError(f"--color-depth applies to PNG and TIFF only, not '{path.suffix}'")
    return file_format


def set_file_format(scene, path: Path, color_depth: str | None) -> None:
    file_format = file_format_of(path, color_depth)
    image = scene.render.image_settings
    compat.set_media_type(image, "IMAGE")
    image.file_format = file_format
    image.color_mode = "RGBA" if file_format in FORMATS_WITH_ALPHA else "RGB"
    if file_format in ("PNG", "TIFF"):
        image.color_depth = color_depth or "8"
    # The path given is the path written: no extension added by Blender.
    scene.render.use_file_extension = False


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

    def render(scene, path):
        try:
            composite.render_wire_over(scene, path, engine, keep_layers=args.over_layers, samples=args.over_samples)
        except composite.CompositeError as exc:
            raise RenderFailed(f"--over {engine}: {exc}") from None

    return render


def render_frames(scene, paths: dict, args, over=None) -> None:
    """Render each frame to its path, with one progress line (or JSON
    object) per frame."""
    for path in dict.fromkeys(paths.values()):
        check_output(path)
    frames = list(paths)
    start_all = time.perf_counter()
    for index, frame in enumerate(frames, start=1):
        path = paths[frame]
        scene.frame_set(frame)
        scene.render.filepath = str(path)
        if path.exists():
            path.unlink()  # so a failed render cannot leave an old image looking new
        start = time.perf_counter()
        try:
            if over is None:
                bpy.ops.render.render(write_still=True, scene=scene.name)
            else:
                over(scene, path)
        except RuntimeError as exc:
            raise RenderFailed(f"frame {frame}: {one_line(exc)}") from None
        seconds = time.perf_counter() - start
        if not path.is_file() or path.stat().st_size == 0:
            raise RenderFailed(f"frame {frame}: no image was written to '{path}'")
        elapsed = time.perf_counter() - start_all
        eta = elapsed / index * (len(frames) - index)
        stats = runtime.stats()
        if args.progress == "json":
            record = {
                "frame": frame, "index": index, "count": len(frames), "seconds": round(seconds, 4),
                "eta_seconds": round(eta, 3), "output": str(path), "stats": stats,
            }
            print(json.dumps(record), flush=True)
            continue
        width, height = _render_size(scene)
        if len(frames) == 1:
            print(f"solidwire: rendered {path} ({width}x{height}) in {_seconds(seconds)}", flush=True)
        else:
            print(
                f"solidwire: frame {index} of {len(frames)} (frame {frame}, {width}x{height}) "
                f"in {_seconds(seconds)} -> {path}; elapsed {_seconds(elapsed)}, ETA {_seconds(eta)}",
                flush=True,
            )
        if args.print_stats:
            print("solidwire: stats " + ", ".join(f"{k}={_format_stat(v)}" for k, v in stats.items()), flush=True)


def _format_stat(value) -> str:
    return f"{value:.2f}" if isinstance(value, float) else str(value)


def _render_size(scene) -> tuple[int, int]:
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(int(r.resolution_x * scale), 1), max(int(r.resolution_y * scale), 1)


def run(arguments: list[str], *, prog: str = "solidwire render", build_demo=None) -> int:
    """Parse ``arguments`` and render. Raises UsageError / RenderFailed."""
    args = build_parser(prog).parse_args(arguments)
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
    if args.output is not None:
        template = output_template(args.output)  # '//' resolves against the file just opened
        set_file_format(scene, template, args.color_depth)
        paths = {frame: frame_path(template, frame, len(frames)) for frame in frames}
    else:
        if args.color_depth is not None:
            raise UsageError("--color-depth needs -o (without it the scene's own format is used)")
        paths = {frame: scene_frame_path(scene, frame) for frame in frames}
        # frame_path() already holds the extension: Blender must not add another.
        scene.render.use_file_extension = False
    over = over_renderer(scene, args)  # before the engine is set: --over SCENE
    scene.render.engine = ENGINE_ID
    render_frames(scene, paths, args, over)
    return 0


def main(arguments: list[str], **kwargs) -> int:
    """Run the command line; return the exit code (never raises)."""
    try:
        return run(arguments, **kwargs)
    except UsageError as exc:
        print(f"solidwire: error: {exc}", file=sys.stderr, flush=True)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("solidwire: interrupted", file=sys.stderr, flush=True)
        return 130
    except RenderFailed as exc:
        print(f"solidwire: error: render failed: {exc}", file=sys.stderr, flush=True)
        return EXIT_FAILURE
    except Exception:  # noqa: BLE001  (a bug: keep the traceback, but never exit 0)
        traceback.print_exc()
        print("solidwire: error: unexpected failure (traceback above)", file=sys.stderr, flush=True)
        return EXIT_FAILURE


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
