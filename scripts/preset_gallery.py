"""Render every built-in SolidWire preset on Suzanne and write a labelled
gallery image (docs/presets.png by default).

    .venv/bin/python -m scripts.preset_gallery [-o docs/presets.png]

Overlay presets (no fill) are composited over Blender's own Solid shading of
the same view (a Workbench render), which is how an artist sees them in the
viewport; fill presets are opaque and replace it. The "Fade into Distance"
cell uses the range that "Fade Range from Visible Objects" sets, as an artist
would. Labels need Pillow; without it the grid is written unlabelled through
Blender's image API, with a warning that names the tiles. The last tile is
not a preset: it is Blender's Solid shading alone, the reference the overlay
presets are drawn over.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

import bpy
import numpy as np

import solidwire_addon
from solidwire_addon.blender import engine, presets
from solidwire_addon.blender.gpu_context import ensure_gpu
from tests.support import scenes

CELL = (460, 345)
COLUMNS = 3
LABEL_HEIGHT = 30
BACKGROUND = (0.045, 0.045, 0.05)  # linear; close to the default viewport grey
LABEL_BACKGROUND = (28, 28, 30)


def srgb_encode(linear: np.ndarray) -> np.ndarray:
    c = np.clip(linear, 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1 / 2.4) - 0.055)


def srgb_decode(encoded: np.ndarray) -> np.ndarray:
    c = np.clip(encoded, 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4))


def build_scene():
    scene = scenes.empty_scene(*CELL)
    scenes.add_camera(scene, location=(2.3, -4.6, 1.4), target=(0.0, 0.0, 0.05), lens=60.0)
    suzanne = scenes.monkey(scene, subdivisions=1)
    suzanne.data.shade_smooth()
    return scene


def solid_shading(scene, folder: Path) -> np.ndarray:
    """Blender's Solid shading of the view (Workbench), linear premultiplied."""
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    straight = scenes.render_to_file(scene, folder / "solid.png")
    scene.render.engine = "SOLIDWIRE"
    rgb = srgb_decode(straight[..., :3]) * straight[..., 3:4]
    return np.concatenate([rgb, straight[..., 3:4]], axis=-1)


def over(top: np.ndarray, bottom_rgb: np.ndarray) -> np.ndarray:
    """Premultiplied ``top`` over an opaque ``bottom_rgb``."""
    return top[..., :3] + (1.0 - top[..., 3:4]) * bottom_rgb


def render_cells(scene, folder: Path):
    ensure_gpu()
    base = solid_shading(scene, folder)
    background = np.broadcast_to(np.asarray(BACKGROUND), base.shape[:2] + (3,))
    shaded = over(base, background)
    cells = []
    for preset in presets.builtin_presets():
        presets.apply(preset, scene.solidwire)
        label = preset.name
        if preset.values.get("use_fade"):
            bpy.ops.solidwire.fade_from_visible()
            props = scene.solidwire
            label += f" (fitted {props.fade_start:.1f}-{props.fade_end:.1f})"
        rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), CELL)
        under = background if preset.values.get("use_fill") else shaded
        cells.append((label, over(rgba, under)))
    cells.append(("Blender Solid shading, no overlay", shaded))
    return cells


def compose(cells, columns: int = COLUMNS, cell=CELL) -> np.ndarray:
    """(H, W, 3) uint8, top row first, with a label strip under each cell."""
    width, height = cell
    rows = -(-len(cells) // columns)
    sheet = np.zeros((rows * (height + LABEL_HEIGHT), columns * width, 3), dtype=np.uint8)
    sheet[:] = LABEL_BACKGROUND
    for index, (_label, linear) in enumerate(cells):
        r, c = divmod(index, columns)
        image = (srgb_encode(linear[::-1]) * 255.0 + 0.5).astype(np.uint8)  # bottom-up -> top-down
        y0 = r * (height + LABEL_HEIGHT)
        sheet[y0 : y0 + height, c * width : (c + 1) * width] = image
    return sheet


def write(sheet: np.ndarray, cells, path: Path, columns: int = COLUMNS, cell=CELL) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        from PIL import Image, ImageDraw, ImageFont
    except ImportError:
        # Without labels a sheet is easy to misread (the last tile of the
        # preset sheet, Blender's Solid shading with no overlay, passed for a
        # preset that draws no wire), so say so and name the tiles.
        print(
            f"warning: Pillow is not installed (`make galleries` installs it), so {path.name} has empty "
            f"label strips; its tiles, "
            f"left to right, top to bottom: {'; '.join(label for label, _linear in cells)}",
            file=sys.stderr,
        )
        _write_with_blender(sheet, path)
        return
    image = Image.fromarray(sheet)
    draw = ImageDraw.Draw(image)
    try:
        font = ImageFont.load_default(size=19)
    except TypeError:  # Pillow < 10.1
        font = ImageFont.load_default()
    width, height = cell
    for index, (label, _linear) in enumerate(cells):
        r, c = divmod(index, columns)
        x = c * width + 10
        y = r * (height + LABEL_HEIGHT) + height + 6
        draw.text((x, y), label, fill=(235, 235, 235), font=font)
    for c in range(1, columns):  # thin separators between columns
        draw.line([(c * width, 0), (c * width, image.height)], fill=LABEL_BACKGROUND, width=2)
    # An adaptive 256-colour palette keeps the anti-aliased lines smooth and
    # the file small enough for the README and the manual.
    image.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(path, optimize=True)


def write_sheet(cells, output: Path, *, columns: int, cell) -> None:
    """Compose ``cells`` (label, image) into one labelled sheet, write it to
    ``output`` and say where and how big."""
    write(compose(cells, columns=columns, cell=cell), cells, output, columns=columns, cell=cell)
    print(f"wrote {output} ({output.stat().st_size // 1024} KiB)")


def _write_with_blender(sheet: np.ndarray, path: Path) -> None:
    height, width, _ = sheet.shape
    image = bpy.data.images.new("solidwire_gallery", width, height, alpha=False)
    rgba = np.ones((height, width, 4), dtype=np.float32)
    rgba[..., :3] = sheet[::-1] / 255.0
    image.pixels.foreach_set(rgba.ravel())
    image.filepath_raw = str(path)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=ROOT / "docs" / "presets.png")
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        scene = build_scene()
        with tempfile.TemporaryDirectory(prefix="solidwire-gallery-") as folder:
            cells = render_cells(scene, Path(folder))
        write(compose(cells), cells, args.output)
    finally:
        solidwire_addon.unregister()
    print(f"wrote {args.output} ({args.output.stat().st_size // 1024} KiB)")
    return 0


def still_life(size, world_name: str, world_color) -> tuple:
    """The galleries' shared scene: Suzanne, a cube, a sphere and a floor under
    one camera, over a world colour. Returns (scene, (suzanne, cube, sphere, floor))."""
    scene = scenes.empty_scene(*size, transparent=False)
    world = bpy.data.worlds.new(world_name)
    world.color = world_color
    scene.world = world
    suzanne = scenes.monkey(scene, subdivisions=1, location=(0.0, 0.0, 0.05), rotation=(0.0, 0.0, -0.35))
    cube = scenes.cube(scene, size=1.1, location=(1.7, 1.2, -0.4), rotation=(0.0, 0.0, 0.6))
    sphere = scenes.uv_sphere(scene, segments=20, rings=10, radius=0.7, location=(-1.9, 1.4, -0.3))
    floor = scenes.grid(scene, "Floor", x_segments=14, y_segments=14, size=16.0, location=(0, 3.0, -1.0))
    scenes.add_camera(scene, location=(2.6, -5.2, 2.2), target=(0.0, 0.6, -0.3), lens=42.0)
    return scene, (suzanne, cube, sphere, floor)


def run_gallery(argv, description: str, default_output: Path, build_scene, render_cells, *, cell=None) -> int:
    """Command line of a 3-column gallery sheet: build, render, compose, write."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("-o", "--output", type=Path, default=default_output)
    args = parser.parse_args(argv)
    solidwire_addon.register()
    try:
        cells = render_cells(build_scene())
        sizing = {} if cell is None else {"cell": cell}
        write(compose(cells, columns=3, **sizing), cells, args.output, columns=3, **sizing)
    finally:
        solidwire_addon.unregister()
    print(f"wrote {args.output} ({args.output.stat().st_size // 1024} KiB)")
    return 0


def render_looks(scene, looks, base: dict, size, *, reset: bool = True) -> list:
    """(label, RGB) for each (label, overrides) of ``looks``: ``base`` plus
    the overrides, drawn in one piece by the engine at ``size``. With
    ``reset`` each cell's overrides go back to their defaults afterwards."""
    ensure_gpu()
    cells = []
    for label, overrides in looks:
        for name, value in {**base, **overrides}.items():
            setattr(scene.solidwire, name, value)
        rgba, _depth = engine.render_scene(bpy.context.evaluated_depsgraph_get(), size)
        cells.append((label, rgba[..., :3]))
        if reset:
            for name in overrides:
                scene.solidwire.property_unset(name)
    return cells


if __name__ == "__main__":
    sys.exit(main())
