"""Wire over a beauty render: the SolidWire pass composited over an EEVEE,
Cycles or Workbench render of the same camera.

Both layers are rendered by Blender itself (``bpy.ops.render.render``) from
the same scene, frame, camera and render size (resolution percentage, lens
shift, pixel aspect and sensor fit all come from the one camera), so they
share the evaluated geometry and line up pixel for pixel: the wire is hidden
exactly where the beauty shows a nearer surface. The layers are written as
uncompressed float multilayer OpenEXR files into a temporary folder (Render
Result pixels cannot be read from Python), read back here, and combined as
premultiplied scene-linear images with a straight alpha-over:

    out = wire + (1 - wire.a) * beauty

The composite is written through a temporary float image and
``Image.save_render`` with the scene's own output format and colour
management, exactly as Blender writes a render. During the two renders:

- motion blur and the render region (border) are off, so both layers show the
  same motion-free full frame;
- the sequencer is off (its strips would replace the render);
- the beauty keeps the scene's film (transparent or world) and, when the
  scene composites, the compositor's output;
- the wire pass uses a transparent film, no compositor and SolidWire's
  overlay mode (fill off), whatever the scene's SolidWire settings say.

Everything the renders change is restored afterwards whatever happens, and
nothing is left in ``bpy.data`` or on disk apart from the requested files.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core import compat, output
from ..core.exr import ExrError, exr_pass, read_exr
from ..core.ids import ENGINE_ID
from ..core.log import one_line

# Friendly and older names of Blender's engines (EEVEE was BLENDER_EEVEE_NEXT
# in Blender 4.2 to 4.4 and is BLENDER_EEVEE again from 5.0).
ENGINE_ALIASES = {
    "EEVEE": ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT"),
    "BLENDER_EEVEE": ("BLENDER_EEVEE", "BLENDER_EEVEE_NEXT"),
    "BLENDER_EEVEE_NEXT": ("BLENDER_EEVEE_NEXT", "BLENDER_EEVEE"),
    "WORKBENCH": ("BLENDER_WORKBENCH",),
}


class CompositeError(Exception):
    """An expected problem (failed render, unwritable output): one line for the user."""


class EngineError(CompositeError):
    """The engine asked for is unknown, unavailable or SolidWire itself."""


# -- engines -------------------------------------------------------------------


def available_engines(scene) -> list[str]:
    """The render engines this Blender offers (identifiers), SolidWire included.

    The engine enum is dynamic (add-on engines join it), so the list comes
    from Blender's own refusal of an impossible name."""
    render = scene.render
    try:
        render.engine = "\x01not-an-engine"
    except TypeError as exc:
        names = re.findall(r"'([^']+)'", str(exc).partition("not found in")[2])
        if names:
            return names
    return ["BLENDER_EEVEE", "BLENDER_WORKBENCH", "CYCLES"]


def resolve_engine(scene, name: str | None) -> str:
    """The engine identifier for ``name`` (case-insensitive, aliases allowed;
    None or '' or 'SCENE' means the scene's engine). Raises CompositeError for
    an unknown or unavailable engine, and for SolidWire itself."""
    requested = (name or "SCENE").strip().upper()
    if requested == "SCENE":
        requested = scene.render.engine
        if requested == ENGINE_ID:
            raise EngineError(
                "the scene's render engine is SolidWire itself; choose the engine of the render "
                "underneath (CYCLES, BLENDER_EEVEE, BLENDER_WORKBENCH)"
            )
    available = available_engines(scene)
    for candidate in ENGINE_ALIASES.get(requested, (requested,)):
        if candidate == ENGINE_ID:
            raise EngineError("the render underneath the wire must come from another engine than SolidWire")
        if candidate in available:
            return candidate
    others = ", ".join(e for e in available if e != ENGINE_ID) or "none"
    raise EngineError(f"unknown or unavailable render engine '{name}' (available: {others})")


# -- OpenEXR -------------------------------------------------------------------


def alpha_over(wire: np.ndarray, beauty: np.ndarray) -> np.ndarray:
    """Premultiplied ``wire`` over premultiplied ``beauty``."""
    wire = np.asarray(wire, dtype=np.float32)
    return wire + (1.0 - wire[..., 3:4]) * np.asarray(beauty, dtype=np.float32)


def check_output_format(scene) -> None:
    """The composite is one still image: the scene's format must be one."""
    settings = scene.render.image_settings
    if getattr(settings, "media_type", "IMAGE") == "VIDEO" or settings.file_format in ("FFMPEG", "AVI_JPEG", "AVI_RAW"):
        raise CompositeError("the scene's output format is a video; choose an image format for the composite")


def save_image(scene, rgba: np.ndarray, path) -> Path:
    """Write premultiplied scene-linear ``rgba`` (H, W, 4, bottom row first)
    with the scene's output format and colour management, as a render is
    written. The temporary image is removed afterwards."""
    import bpy

    path = Path(path).absolute()
    check_output_format(scene)
    path.parent.mkdir(parents=True, exist_ok=True)
    height, width = rgba.shape[:2]
    image = bpy.data.images.new("SolidWire Composite", width, height, alpha=True, float_buffer=True)
    try:
        # Float images hold premultiplied scene-linear pixels.
        image.colorspace_settings.name = _scene_linear_name(image)
        image.pixels.foreach_set(np.ascontiguousarray(rgba, dtype=np.float32).ravel())
        image.save_render(str(path), scene=scene)
    finally:
        bpy.data.images.remove(image)
    if not path.is_file():
        raise CompositeError(f"no image was written to '{path}'")
    return path


def _scene_linear_name(image) -> str:
    items = [e.identifier for e in image.colorspace_settings.bl_rna.properties["name"].enum_items]
    for name in ("Linear Rec.709", "Linear", "Linear CIE-XYZ E"):
        if name in items:
            return name
    return image.colorspace_settings.name


# -- rendering -----------------------------------------------------------------


@contextlib.contextmanager
def preserved(*owners_and_names):
    """Restore ``owner.name`` for each (owner, names) pair on exit, in the
    order given (so a format's family is restored before the format)."""
    saved = [(owner, name, getattr(owner, name)) for owner, names in owners_and_names for name in names]
    try:
        yield
    finally:
        for owner, name, value in saved:
            try:
                setattr(owner, name, value)
            except (AttributeError, TypeError, ValueError):
                pass  # e.g. an engine that went away meanwhile


_IMAGE_SETTINGS = ("media_type", "file_format", "color_mode", "color_depth", "exr_codec", "color_management")
_RENDER_SETTINGS = (
    "engine",
    "filepath",
    "use_file_extension",
    "use_motion_blur",
    "use_border",
    "film_transparent",
    "use_compositing",
    "use_sequencer",
)


def _exr_output(scene, multilayer: bool) -> None:
    """Float EXR output: the image itself (the compositor's output when the
    scene composites) or, for the Depth passes, every pass of the layer.

    (A multilayer file also holds every other pass the view layer has on,
    and Blender 5.0 fails to write one with more than one pass and
    non-square pixels: "Conflicting attributes ... pixelAspectRatio".)"""
    image = scene.render.image_settings
    compat.set_media_type(image, "MULTI_LAYER_IMAGE" if multilayer else "IMAGE")  # Blender 5: the family first
    image.file_format = "OPEN_EXR_MULTILAYER" if multilayer else "OPEN_EXR"
    image.color_mode = "RGBA"
    image.color_depth = "32"
    image.exr_codec = "NONE"
    if hasattr(image, "color_management"):
        image.color_management = "FOLLOW_SCENE"
    scene.render.use_file_extension = False


@contextlib.contextmanager
def _quiet_stdout():
    """Blender's own lines for the temporary layer files (``Saved: '...'``,
    ``Fra:`` progress) go nowhere: the user asked for the composite only,
    and the command line reports that one. Errors (stderr) still show. C
    code writes to file descriptor 1 directly, so the descriptor itself is
    redirected (Blender flushes its stdout after each of these lines)."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:  # no real stdout (embedded consoles): nothing to hide
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


def _render_to(scene, engine: str, path: Path, layer: str) -> dict:
    import bpy

    scene.render.engine = engine
    scene.render.filepath = str(path)
    try:
        with _quiet_stdout():
            bpy.ops.render.render(write_still=True, scene=scene.name, layer=layer)
    except RuntimeError as exc:
        raise CompositeError(f"{engine} render failed: {one_line(exc)}") from None
    if not path.is_file():
        raise CompositeError(f"{engine} render wrote no image (see Blender's messages above)")
    try:
        return read_exr(path)
    except ExrError as exc:
        raise CompositeError(str(exc)) from None


def _view_layer(scene, view_layer=None):
    if view_layer is not None:
        return view_layer
    import bpy

    context_layer = getattr(bpy.context, "view_layer", None)
    if context_layer is not None and getattr(bpy.context, "scene", None) == scene:
        return context_layer
    for layer in scene.view_layers:
        if layer.use:
            return layer
    return scene.view_layers[0]


@dataclass
class Layers:
    """Premultiplied scene-linear RGBA (H, W, 4), bottom row first, and the
    view depth (H, W) of each layer when asked for (1e10 where empty)."""

    beauty: np.ndarray
    wire: np.ndarray
    composite: np.ndarray
    engine: str
    beauty_depth: np.ndarray | None = None
    wire_depth: np.ndarray | None = None


def check_inputs(scene, engine=None, *, depth: bool = False) -> str:
    """Everything about the scene a wire-over render needs, checked before
    rendering; returns the beauty's engine identifier."""
    if scene.camera is None:
        raise CompositeError(f"scene '{scene.name}' has no camera")
    if scene.render.use_multiview:
        raise CompositeError("stereo / multi-view renders are not supported (switch Stereoscopy off)")
    if depth and scene.render.pixel_aspect_x != scene.render.pixel_aspect_y:
        raise CompositeError("Blender cannot write Depth passes with non-square pixels (pixel aspect)")
    return resolve_engine(scene, engine)


def render_layers(
    scene,
    engine=None,
    *,
    view_layer=None,
    samples: int | None = None,
    depth: bool = False,
    keep_exr: Path | None = None,
) -> Layers:
    """Render the beauty with ``engine`` (default: the scene's) and the wire
    with SolidWire, and composite them. Restores every setting it touches.

    ``samples`` overrides the beauty's sample count (Cycles, EEVEE) for this
    render; ``depth`` also returns both Depth passes; ``keep_exr`` (a path
    stem) keeps the two float layers as ``STEM.beauty.exr`` and
    ``STEM.wire.exr``."""
    engine = check_inputs(scene, engine, depth=depth)
    layer = _view_layer(scene, view_layer)
    tmp = Path(tempfile.mkdtemp(prefix="solidwire-over-"))
    try:
        beauty_exr, wire_exr = _render_both(scene, engine, layer, tmp, samples=samples, depth=depth)
        result = _composite(beauty_exr, wire_exr, layer.name, engine, depth)
        if keep_exr is not None:
            _keep_layers(tmp, Path(keep_exr).absolute())
        return result
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _render_both(scene, engine: str, layer, tmp: Path, *, samples, depth: bool) -> tuple[dict, dict]:
    """The beauty and the wire rendered into ``tmp`` as float EXR layers,
    read back; every setting changed for them is restored afterwards."""
    settings = scene.solidwire
    render = scene.render
    restores = [
        (render, _RENDER_SETTINGS),
        (render.image_settings, [n for n in _IMAGE_SETTINGS if hasattr(render.image_settings, n)]),
        (layer, ("use_pass_z",)),
        (settings, ("use_fill",)),
    ]
    if samples is not None:
        restores += [(scene.cycles, ("samples",))] if hasattr(scene, "cycles") else []
        restores += [(scene.eevee, ("taa_render_samples",))]
    with preserved(*restores):
        _exr_output(scene, multilayer=depth)
        render.use_motion_blur = False
        render.use_border = False
        render.use_sequencer = False
        if depth:
            layer.use_pass_z = True
        if samples is not None:
            if hasattr(scene, "cycles"):
                scene.cycles.samples = samples
            scene.eevee.taa_render_samples = samples

        beauty_exr = _render_to(scene, engine, tmp / "beauty.exr", layer.name)

        render.film_transparent = True
        render.use_compositing = False
        settings.use_fill = False
        wire_exr = _render_to(scene, ENGINE_ID, tmp / "wire.exr", layer.name)
    return beauty_exr, wire_exr


def _composite(beauty_exr: dict, wire_exr: dict, layer_name: str, engine: str, depth: bool) -> Layers:
    beauty = _combined(beauty_exr, layer_name, engine)
    wire = _combined(wire_exr, layer_name, ENGINE_ID)
    if beauty.shape != wire.shape:
        raise CompositeError(
            f"the beauty ({beauty.shape[1]}x{beauty.shape[0]}) and the wire "
            f"({wire.shape[1]}x{wire.shape[0]}) differ in size"
        )
    result = Layers(beauty, wire, alpha_over(wire, beauty), engine)
    if depth:
        result.beauty_depth = _depth(beauty_exr, layer_name)
        result.wire_depth = _depth(wire_exr, layer_name)
    return result


def _keep_layers(tmp: Path, stem: Path) -> None:
    """Copy the two float layers next to the output as STEM.beauty.exr / STEM.wire.exr."""
    stem.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(tmp / "beauty.exr", stem.with_name(stem.name + ".beauty.exr"))
    shutil.copyfile(tmp / "wire.exr", stem.with_name(stem.name + ".wire.exr"))


def _combined(channels: dict, layer: str, engine: str) -> np.ndarray:
    if all(c in channels for c in "RGBA"):  # a single-layer file: the image
        return np.stack([channels[c] for c in "RGBA"], axis=-1)
    # Multilayer: with the compositor on, the "Composite" layer is the image
    # the user sees as the render; otherwise the view layer's Combined pass.
    for name in ("Composite", layer):
        rgba = exr_pass(channels, name, "Combined", "RGBA")
        if rgba is not None:
            return rgba
    layers = sorted({key.rsplit(".", 2)[0] for key in channels})
    raise CompositeError(
        f"the {engine} render holds no Combined pass for view layer '{layer}' (layers: {', '.join(layers) or 'none'})"
    )


def _depth(channels: dict, layer: str) -> np.ndarray | None:
    z = exr_pass(channels, layer, "Depth", "Z")
    return None if z is None else z[..., 0]


def render_wire_over(scene, filepath, engine=None, *, keep_layers: bool = False, layers_name=None, **kwargs) -> Layers:
    """Render the wire over ``engine``'s render and write the composite to
    ``filepath`` in the scene's output format (plus ``NAME.beauty.exr`` and
    ``NAME.wire.exr`` beside it with ``keep_layers``; NAME from
    ``layers_name`` when the composite goes to a temporary name first).
    Returns the layers."""
    path = Path(os.fspath(filepath)).absolute()
    # Before the (slow) renders: bad input or a path that cannot be written
    # costs nothing.
    check_inputs(scene, engine)
    check_output_format(scene)
    try:
        output.check_output(path)
    except output.OutputError as exc:
        raise CompositeError(str(exc)) from None
    named = Path(os.fspath(layers_name)).absolute() if layers_name is not None else path
    keep = named.with_name(named.stem) if keep_layers else None
    layers = render_layers(scene, engine, keep_exr=keep, **kwargs)
    save_image(scene, layers.composite, path)
    return layers
