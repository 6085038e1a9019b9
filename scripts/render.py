"""Render a scene (or the built-in demo) with the SolidWire engine from the
command line. The same options work both ways:

    python scripts/render.py SCENE.blend -o OUT.png [options]          (bpy module)
    blender -b SCENE.blend --python scripts/render.py -- -o OUT.png [options]

Inside Blender the .blend named on Blender's own command line is already open
(a SCENE.blend after ``--`` is opened instead). ``--demo`` renders a built-in
demo scene instead of a file. Options override the scene's ``scene.solidwire``
settings for this render only; the .blend is never saved.

The image is rendered through the real engine (``scene.render.engine =
'SOLIDWIRE'`` and ``bpy.ops.render.render(write_still=True)``), so it is the
same image ``blender -b SCENE.blend -E SOLIDWIRE -f 1`` writes.

Expected problems (missing or unreadable file, no camera, unwritable output,
bad option values) end with one line ``solidwire: error: ...`` on stderr and
exit code 2; an unexpected failure exits with code 1.
"""

from __future__ import annotations

import argparse
import importlib
import math
import os
import re
import sys
import tempfile
import time
import traceback
from pathlib import Path

import bpy

SCRIPT_DIR = Path(__file__).resolve().parent
REPO_ROOT = SCRIPT_DIR.parent
ENGINE_ID = "SOLIDWIRE"
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


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="solidwire",
        description="Render a .blend (or the built-in demo) with the SolidWire engine.",
        epilog="Inside Blender: blender -b SCENE.blend --python scripts/render.py -- -o OUT.png [options]",
    )
    parser.add_argument("blend", nargs="?", metavar="SCENE.blend", help="the .blend file to render")
    parser.add_argument("--demo", action="store_true", help="render the built-in demo scene instead of a .blend")
    parser.add_argument(
        "-o", "--output", required=True, metavar="OUT.png",
        help="image file to write (.png, .jpg, .tif, .exr, .webp, .bmp); '#' characters become the frame number",
    )
    parser.add_argument("--scene", metavar="NAME", help="scene to render (default: the file's active scene)")
    parser.add_argument("--camera", metavar="NAME", help="camera object to render from (default: the scene camera)")
    parser.add_argument("--frames", type=_frame_range, metavar="A-B", help="frame or frame range (default: current frame)")

    look = parser.add_argument_group("line settings (override scene.solidwire)")
    look.add_argument("--thickness", type=_finite_float, metavar="PX", help="full width of an interior edge's core, px")
    look.add_argument("--softness", type=_finite_float, metavar="PX", help="anti-aliased falloff, px")
    look.add_argument("--wire-color", type=_color, metavar="R,G,B[,A]", help="wire colour (0..1 or #RRGGBB)")
    look.add_argument("--fill", action=argparse.BooleanOptionalAction, default=None, help="opaque fill under the wire")
    look.add_argument("--fill-color", type=_color, metavar="R,G,B[,A]", help="fill colour")
    look.add_argument("--diagonals", choices=("HIDDEN", "SOLID", "DOTTED", "DASHED"), type=str.upper,
                      help="how quad and n-gon diagonals are drawn")
    look.add_argument("--pattern-period", type=_finite_float, metavar="PX", help="dotted/dashed period, px")
    look.add_argument("--pattern-duty", type=_finite_float, metavar="Q", help="dotted/dashed duty cycle, 0..1")
    look.add_argument("--fade", type=_finite_float, nargs=2, metavar=("START", "END"),
                      help="fade the wire out between these view depths (scene units)")
    look.add_argument("--no-fade", action="store_true", help="switch depth fade off")
    styles = parser.add_argument_group("line styles beyond the papers (override scene.solidwire)")
    styles.add_argument("--thickness-mode", choices=("PIXELS", "WORLD", "DEPTH"), type=str.upper,
                        help="constant px, a width in scene units, or a depth cue from --thickness to --thickness-far")
    styles.add_argument("--world-thickness", type=_finite_float, metavar="UNITS", help="core width in scene units (WORLD)")
    styles.add_argument("--thickness-far", type=_finite_float, metavar="PX", help="core width at the far depth (DEPTH)")
    styles.add_argument("--thickness-depth", type=_finite_float, nargs=2, metavar=("NEAR", "FAR"),
                        help="view depths where the depth cue starts and ends (DEPTH)")
    styles.add_argument("--silhouettes", action=argparse.BooleanOptionalAction, default=None,
                        help="full-width silhouette and boundary edges (their outer half too)")
    styles.add_argument("--hidden-lines", action=argparse.BooleanOptionalAction, default=None,
                        help="also draw hidden edges, dimmed and dashed")
    styles.add_argument("--hidden-alpha", type=_finite_float, metavar="A", help="opacity of hidden edges, 0..1")
    styles.add_argument("--hidden-period", type=_finite_float, metavar="PX", help="dash period of hidden edges, px")
    styles.add_argument("--hidden-duty", type=_finite_float, metavar="Q", help="dash duty of hidden edges, 0..1")
    look.add_argument("--backface-culling", action=argparse.BooleanOptionalAction, default=None,
                      help="back faces neither draw nor occlude")

    image = parser.add_argument_group("image")
    film = image.add_mutually_exclusive_group()
    film.add_argument("--transparent", dest="transparent", action="store_true", default=None,
                      help="transparent film (alpha where nothing is drawn)")
    film.add_argument("--opaque", dest="transparent", action="store_false", help="world colour behind the meshes")
    image.add_argument("--width", type=_positive_int, metavar="PX", help="resolution X")
    image.add_argument("--height", type=_positive_int, metavar="PX", help="resolution Y")
    image.add_argument("--percentage", type=_positive_int, metavar="PCT", help="resolution percentage")
    image.add_argument("--color-depth", choices=("8", "16"), help="bits per channel for PNG/TIFF (default 8)")
    parser.add_argument("--print-stats", action="store_true", help="print solidwire stats() after each frame")

    over = parser.add_argument_group("wire over a render (solidwire_addon/composite.py)")
    over.add_argument("--over", metavar="ENGINE",
                      help="render the image underneath with ENGINE (CYCLES, BLENDER_EEVEE or EEVEE, "
                           "BLENDER_WORKBENCH or WORKBENCH, SCENE = the file's engine) and write the "
                           "SolidWire pass composited over it")
    over.add_argument("--over-samples", type=_positive_int, metavar="N",
                      help="samples of the render underneath (Cycles, EEVEE; default: the scene's)")
    over.add_argument("--over-layers", action="store_true",
                      help="also write the two float layers as NAME.beauty.exr and NAME.wire.exr")
    return parser


def script_arguments(argv: list[str]) -> list[str]:
    """The arguments meant for this script.

    Inside the Blender executable everything before ``--`` belongs to
    Blender; with the bpy module, Python's own argv is ours. (The bpy module
    leaves ``bpy.app.binary_path`` empty.)"""
    if bpy.app.binary_path:
        return argv[argv.index("--") + 1 :] if "--" in argv else []
    return argv[1:]


# -- set-up --------------------------------------------------------------------


def registered_engine():
    for cls in bpy.types.RenderEngine.__subclasses__():
        # A disabled add-on's class object lives on (its module still holds
        # it), so registration is checked, not existence.
        if getattr(cls, "bl_idname", None) == ENGINE_ID and getattr(cls, "is_registered", False):
            return cls
    return None


def ensure_addon():
    """(package, registered_here): the installed, enabled extension if there
    is one (Blender registered it at start-up), else this repository's
    package, registered now."""
    engine = registered_engine()
    if engine is not None and hasattr(bpy.types.Scene, "solidwire"):
        # e.g. bl_ext.user_default.solidwire.solidwire_addon.engine -> ...solidwire_addon
        return importlib.import_module(engine.__module__.rpartition(".")[0]), False
    if str(REPO_ROOT) not in sys.path:
        sys.path.insert(0, str(REPO_ROOT))
    import solidwire_addon

    solidwire_addon.register()
    return solidwire_addon, True


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
        raise UsageError(f"cannot open '{path}': {_one_line(exc)}") from None


def load_scene(args):
    """Open what is to be rendered and return its scene."""
    if args.demo:
        if args.blend:
            raise UsageError("give either SCENE.blend or --demo, not both")
        sys.path.insert(0, str(SCRIPT_DIR))
        import demo_scene

        return demo_scene.build()
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


def _rna_limits(owner, name):
    prop = owner.bl_rna.properties[name]
    return prop.hard_min, prop.hard_max


def _checked(owner, name: str, value, option: str):
    """``value`` if it lies inside the property's hard range (Blender would
    otherwise clamp it silently)."""
    low, high = _rna_limits(owner, name)
    values = value if isinstance(value, tuple) else (value,)
    if any(v < low or v > high for v in values):
        raise UsageError(f"{option} {value if not isinstance(value, tuple) else ','.join(map(str, value))} "
                         f"is out of range [{low:g}, {high:g}]")
    return value


def apply_options(scene, args) -> None:
    settings = scene.solidwire
    if args.diagonals is not None:
        # Set first: choosing a pattern mode resets the duty to its default.
        settings.diagonal_mode = args.diagonals
    for option, name in (
        ("thickness", "thickness"),
        ("softness", "softness"),
        ("wire_color", "wire_color"),
        ("fill_color", "fill_color"),
        ("pattern_period", "pattern_period"),
        ("pattern_duty", "pattern_duty"),
        ("world_thickness", "world_thickness"),
        ("thickness_far", "thickness_far"),
        ("hidden_alpha", "hidden_alpha"),
        ("hidden_period", "hidden_period"),
        ("hidden_duty", "hidden_duty"),
    ):
        value = getattr(args, option)
        if value is not None:
            setattr(settings, name, _checked(settings, name, value, "--" + option.replace("_", "-")))
    if args.fill is not None:
        settings.use_fill = args.fill
    if args.thickness_mode is not None:
        settings.thickness_mode = args.thickness_mode
    if args.thickness_depth is not None:
        near, far = args.thickness_depth
        settings.thickness_depth_start = _checked(settings, "thickness_depth_start", near, "--thickness-depth NEAR")
        settings.thickness_depth_end = _checked(settings, "thickness_depth_end", far, "--thickness-depth FAR")
    if args.silhouettes is not None:
        settings.use_silhouettes = args.silhouettes
    if args.hidden_lines is not None:
        settings.use_hidden_lines = args.hidden_lines
    if args.backface_culling is not None:
        settings.use_backface_culling = args.backface_culling
    if args.fade is not None and args.no_fade:
        raise UsageError("give either --fade or --no-fade, not both")
    if args.fade is not None:
        start, end = args.fade
        settings.fade_start = _checked(settings, "fade_start", start, "--fade START")
        settings.fade_end = _checked(settings, "fade_end", end, "--fade END")
        settings.use_fade = True
    if args.no_fade:
        settings.use_fade = False

    render = scene.render
    if args.transparent is not None:
        render.film_transparent = args.transparent
    if args.width is not None:
        render.resolution_x = _checked(render, "resolution_x", args.width, "--width")
    if args.height is not None:
        render.resolution_y = _checked(render, "resolution_y", args.height, "--height")
    if args.percentage is not None:
        render.resolution_percentage = _checked(render, "resolution_percentage", args.percentage, "--percentage")

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


# -- output --------------------------------------------------------------------


def output_template(text: str) -> Path:
    """The -o path made absolute ('//' means next to the .blend, as in Blender)."""
    if text.startswith("//"):
        if not bpy.data.filepath:
            raise UsageError(f"-o '{text}' is relative to the .blend, but no .blend is open")
        text = bpy.path.abspath(text)
    return Path(text).expanduser().absolute()


def frame_path(template: Path, frame: int, frame_count: int) -> Path:
    """Blender's rule: the last run of '#' becomes the zero-padded frame
    number. A range rendered to a name without '#' gets 4 digits appended
    to the name (before the extension), so frames never overwrite each other."""
    name = template.name
    runs = list(re.finditer(r"#+", name))
    if runs:
        run = runs[-1]
        number = f"{frame:0{len(run.group())}d}" if frame >= 0 else f"-{-frame:0{len(run.group()) - 1}d}"
        return template.with_name(name[: run.start()] + number + name[run.end() :])
    if frame_count > 1:
        return template.with_name(f"{template.stem}{frame:04d}{template.suffix}")
    return template


def check_output_folder(directory: Path) -> None:
    """Create the folder if needed (as Blender does) and prove it writable."""
    existing = directory
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise UsageError(f"cannot write to '{directory}': '{existing}' is a file, not a folder")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"cannot create output folder '{directory}': {exc.strerror}") from None
    try:
        # A real write, not os.access: also right for read-only mounts and root.
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".solidwire-write-test-"):
            pass
    except OSError as exc:
        raise UsageError(f"cannot write to '{directory}': {exc.strerror}") from None


def check_output(path: Path) -> None:
    """Fail before rendering if the image cannot be written there."""
    if path.is_dir():
        raise UsageError(f"output '{path}' is a directory")
    check_output_folder(path.parent)
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


def set_file_format(scene, path: Path, color_depth: str | None) -> None:
    file_format = file_format_of(path, color_depth)
    image = scene.render.image_settings
    if hasattr(image, "media_type"):  # Blender 5 picks the family (image/video) first
        image.media_type = "IMAGE"
    image.file_format = file_format
    image.color_mode = "RGBA" if file_format in FORMATS_WITH_ALPHA else "RGB"
    if file_format in ("PNG", "TIFF"):
        image.color_depth = color_depth or "8"
    # The path given is the path written: no extension added by Blender.
    scene.render.use_file_extension = False


# -- rendering -----------------------------------------------------------------


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _seconds(value: float) -> str:
    return f"{value:.2f} s"


def over_renderer(addon, scene, args):
    """With --over: a function (scene, path) that renders the wire over the
    chosen engine's render; the engine is checked now (exit 2 if unknown)."""
    if args.over is None:
        if args.over_samples is not None or args.over_layers:
            raise UsageError("--over-samples and --over-layers need --over ENGINE")
        return None
    composite = importlib.import_module(addon.__name__ + ".composite")
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


def render_frames(scene, template: Path, frames: list[int], addon, print_stats: bool, over=None) -> None:
    paths = [frame_path(template, frame, len(frames)) for frame in frames]
    for path in dict.fromkeys(paths):
        check_output(path)
    start_all = time.perf_counter()
    for index, (frame, path) in enumerate(zip(frames, paths), start=1):
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
            raise RenderFailed(f"frame {frame}: {_one_line(exc)}") from None
        seconds = time.perf_counter() - start
        if not path.is_file() or path.stat().st_size == 0:
            raise RenderFailed(f"frame {frame}: no image was written to '{path}'")
        width, height = _render_size(scene)
        if len(frames) == 1:
            print(f"solidwire: rendered {path} ({width}x{height}) in {_seconds(seconds)}", flush=True)
        else:
            elapsed = time.perf_counter() - start_all
            eta = elapsed / index * (len(frames) - index)
            print(
                f"solidwire: frame {index} of {len(frames)} (frame {frame}, {width}x{height}) "
                f"in {_seconds(seconds)} -> {path}; elapsed {_seconds(elapsed)}, ETA {_seconds(eta)}",
                flush=True,
            )
        if print_stats:
            stats = addon.stats()
            print("solidwire: stats " + ", ".join(f"{k}={_format_stat(v)}" for k, v in stats.items()), flush=True)


def _format_stat(value) -> str:
    return f"{value:.2f}" if isinstance(value, float) else str(value)


def _render_size(scene) -> tuple[int, int]:
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(int(r.resolution_x * scale), 1), max(int(r.resolution_y * scale), 1)


def run(argv: list[str]) -> int:
    args = build_parser().parse_args(script_arguments(argv))
    if not args.demo and not args.blend and not bpy.app.binary_path:
        raise UsageError("no scene given: pass SCENE.blend or --demo")
    file_format_of(Path(args.output), args.color_depth)  # before any slow work
    if not args.output.startswith("//"):
        # Fail before the (possibly slow) file load when the folder is unusable.
        check_output_folder(output_template(args.output).parent)
    addon, registered_here = ensure_addon()
    try:
        scene = load_scene(args)
        template = output_template(args.output)  # '//' resolves against the file just opened
        apply_options(scene, args)
        set_file_format(scene, template, args.color_depth)
        over = over_renderer(addon, scene, args)  # before the engine is set: --over SCENE
        scene.render.engine = ENGINE_ID
        first, last = args.frames if args.frames else (scene.frame_current, scene.frame_current)
        render_frames(scene, template, list(range(first, last + 1)), addon, args.print_stats, over)
    finally:
        if registered_here:
            # Release GPU resources while the GPU still exists: nothing else
            # unregisters a package registered by hand, and freeing them at
            # interpreter exit crashes the process after the image is written.
            addon.unregister()
    return 0


def main(argv: list[str]) -> int:
    try:
        return run(argv)
    except UsageError as exc:
        print(f"solidwire: error: {exc}", file=sys.stderr, flush=True)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("solidwire: interrupted", file=sys.stderr, flush=True)
        return 130
    except RenderFailed as exc:
        print(f"solidwire: error: render failed: {exc}", file=sys.stderr, flush=True)
        return EXIT_FAILURE
    except Exception:  # a bug: keep the traceback, but never exit 0
        traceback.print_exc()
        print("solidwire: error: unexpected failure (traceback above)", file=sys.stderr, flush=True)
        return EXIT_FAILURE


if __name__ == "__main__":
    code = main(sys.argv)
    # Inside Blender a script that returns lets Blender exit 0, so a failure
    # must leave through SystemExit; with the bpy module the same is harmless.
    if code:
        sys.exit(code)
