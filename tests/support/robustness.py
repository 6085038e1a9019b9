"""Helpers for the robustness tests: float renders through the real
engine, captured messages, and scans of the add-on's module state."""

from __future__ import annotations

import sys
import types
from pathlib import Path

import bpy
import numpy as np

from solidwire_addon.blender import overlay
from solidwire_addon.blender.views import camera_view
from tests.support import scenes


def render_exr(scene, path: Path) -> np.ndarray:
    """Render ``scene`` through the SOLIDWIRE engine (``bpy.ops.render.render``
    with ``write_still``: an error the engine reports raises RuntimeError) to a
    32-bit float OpenEXR file, and read it back: (H, W, 4) float32, bottom row
    first, premultiplied (alpha = wire alpha * I on a transparent film). Unlike
    a PNG, the file keeps NaN and Inf, so a poisoned pixel cannot hide."""
    path = scenes.render_still(
        scene, path, file_format="OPEN_EXR", color_mode="RGBA", color_depth="32", exr_codec="ZIP"
    )
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def lines_of(text: str, needle: str) -> list[str]:
    return [line for line in text.splitlines() if needle in line]


def addon_modules() -> list[types.ModuleType]:
    return [
        m for name, m in sorted(sys.modules.items()) if name == "solidwire_addon" or name.startswith("solidwire_addon.")
    ]


def _walk(value, path, found, predicate, depth, seen):
    if id(value) in seen or depth > 4:
        return
    seen.add(id(value))
    if predicate(value):
        found.append(path)
        return
    if isinstance(value, (str, bytes, int, float, bool, type(None), types.ModuleType, types.FunctionType, type)):
        return
    if isinstance(value, np.ndarray):
        return
    if isinstance(value, dict):
        for key, item in list(value.items()):
            _walk(key, f"{path}[key {key!r}]", found, predicate, depth + 1, seen)
            _walk(item, f"{path}[{key!r}]", found, predicate, depth + 1, seen)
    elif isinstance(value, (list, tuple, set, frozenset)):
        for index, item in enumerate(list(value)):
            _walk(item, f"{path}[{index}]", found, predicate, depth + 1, seen)
    elif hasattr(value, "__dict__") and type(value).__module__.startswith("solidwire_addon"):
        for key, item in list(vars(value).items()):
            _walk(item, f"{path}.{key}", found, predicate, depth + 1, seen)


def scan_module_state(predicate) -> list[str]:
    """Paths ('module.name[...]') of every value in the add-on's module
    globals (and the containers and add-on objects they hold, a few levels
    deep) for which ``predicate(value)`` is true."""
    found: list[str] = []
    seen: set = set()
    for module in addon_modules():
        for name, value in list(vars(module).items()):
            if name.startswith("__"):
                continue
            _walk(value, f"{module.__name__}.{name}", found, predicate, 0, seen)
    return found


def is_gpu_object(value) -> bool:
    import gpu

    return type(value).__module__ == "gpu.types" or isinstance(
        value,
        tuple(
            t
            for t in (getattr(gpu.types, n, None) for n in dir(gpu.types))
            if isinstance(t, type) and t.__name__.startswith("GPU")
        ),
    )


def is_blender_data(value) -> bool:
    return isinstance(value, bpy.types.bpy_struct)


def image_alpha(scene, path: str, png: Path) -> np.ndarray:
    """The wire's alpha of ``scene`` through ``path``: "overlay" (the
    viewport overlay's first redraw, Viewport) or "render" (an F12 written
    to ``png``)."""
    if path == "overlay":
        from solidwire_addon.blender.gpu_context import ensure_gpu

        ensure_gpu()
        return Viewport(scene.render.resolution_x, scene.render.resolution_y).draw(scene)[1]
    return scenes.render_to_file(scene, png)[..., 3]


def cube_beside(scene, bad_location=(2.6, 0.0, 0.0)):
    """A reference object on the left of the view and a camera that also
    sees ``bad_location`` on the right, where the faulty object goes."""
    scenes.cube(scene, "GoodCube", size=1.6, location=(-1.6, 0.0, 0.0))
    scenes.add_camera(scene, location=(0.5, -9.0, 2.0), target=(0.5, 0.0, 0.0), lens=35.0)
    return bad_location


class Viewport:
    """An offscreen stand-in for a 3D viewport's framebuffer (no 3D viewport
    exists headless); the overlay draws into it exactly as into a region."""

    def __init__(self, width=64, height=48):
        import gpu

        self.size = (width, height)
        self.color = gpu.types.GPUTexture((width, height), format="SRGB8_A8")
        self.depth = gpu.types.GPUTexture((width, height), format="DEPTH32F_STENCIL8")
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=(self.color,))

    def draw(self, scene, depsgraph=None) -> tuple[dict, np.ndarray]:
        """The overlay over Blender's Solid shading depth of the scene's
        visible objects (viewport.draw_scene_depth): (stats, alpha).
        ``scene_depth`` keeps the view depth of that Solid shading depth
        (+inf where it holds nothing), read before the overlay draws."""
        import gpu

        from tests.support.viewport import draw_scene_depth

        depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, self.size)
        with self.framebuffer.bind():
            self.framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
        visible = [obj for obj in scene.objects if obj.visible_get()]
        draw_scene_depth(self.framebuffer, self.size, depsgraph, view, visible)
        self.view = view
        self.scene_depth = self._view_depth(view)
        with self.framebuffer.bind():
            gpu.state.viewport_set(0, 0, *self.size)
            stats = overlay.draw_scene_overlay(depsgraph, view, scene.solidwire.snapshot())
        buf = self.color.read()
        buf.dimensions = self.size[0] * self.size[1] * 4
        alpha = np.array(buf, dtype=np.float64).reshape(self.size[1], self.size[0], 4)[..., 3] / 255.0
        return stats, alpha

    def hides(self, depth: np.ndarray) -> np.ndarray:
        """(H, W) bool: where the Solid shading depth of the last draw lies
        nearer than view depth ``depth`` (+inf: none) by more than half the
        overlay's depth bias (OVERLAY_DEPTH_BIAS in NDC), so that a surface
        of the overlay's at ``depth`` cannot show there."""
        from solidwire_addon.core.view import OVERLAY_DEPTH_BIAS

        finite = np.isfinite(depth)
        slope = self._ndc_per_view_depth(np.where(finite, depth, 1.0))
        return self.scene_depth < np.where(finite, depth - 0.5 * OVERLAY_DEPTH_BIAS / slope, np.inf)

    def _ndc_per_view_depth(self, depth: np.ndarray) -> np.ndarray:
        """d(NDC z) / d(view depth) of the last draw's projection at finite
        view depths ``depth``."""
        p = np.asarray(self.view.projection, dtype=np.float64)
        w = p[3, 3] - p[3, 2] * depth
        return abs(p[3, 2] * p[2, 3] - p[2, 2] * p[3, 3]) / (w * w)

    def within_bias(self, depth: np.ndarray, behind: np.ndarray) -> np.ndarray:
        """(H, W) bool: where a surface at view depth ``behind`` lies behind
        the visible one at ``depth`` by less than twice what the overlay
        moves its surfaces towards the camera (OVERLAY_DEPTH_BIAS in NDC and
        view.blender_depth_allowance), so that Blender's depth test cannot
        tell them apart (image model §5.6): both show, or a hidden layer
        there does not."""
        from solidwire_addon.core.view import OVERLAY_DEPTH_BIAS, blender_depth_allowance

        finite = np.isfinite(depth) & np.isfinite(behind)
        d = np.where(finite, depth, 1.0)
        a, b, c, e = blender_depth_allowance(self.view)
        shift = OVERLAY_DEPTH_BIAS / self._ndc_per_view_depth(d) + np.minimum(a + b * np.abs(d), c + e * np.abs(d))
        return finite & (np.where(finite, behind, 0.0) - d < 2.0 * shift)

    def blender_decides(self, ref) -> np.ndarray:
        """(H, W) bool: where Blender's depth, not the model, decides what
        the overlay shows (image model §5.6), for a reference asked for its
        depth layers: Blender's surface lies nearer than the model's; a
        surface of ours, or the nearest point of an outer half the model
        hides, lies behind the visible one within the overlay's shift; or
        two of our triangles lie on one another at the visible depth."""
        decides = self.hides(ref.depth) | self.within_bias(ref.depth, ref.next_depth)
        return decides | self.within_bias(ref.depth, ref.hidden_outer_depth) | (ref.level_hits > 1)

    def _view_depth(self, view) -> np.ndarray:
        """(H, W) float64 view depth of what the depth buffer holds now
        (+inf where it is clear), through the view's projection: window
        depth n = z/w with clip z = P22 (-d) + P23, clip w = P32 (-d) + P33."""
        width, height = self.size
        with self.framebuffer.bind():
            buf = self.framebuffer.read_depth(0, 0, width, height)
        buf.dimensions = width * height
        window = np.array(buf, dtype=np.float64).reshape(height, width)
        p = np.asarray(view.projection, dtype=np.float64)
        ndc = 2.0 * window - 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            depth = (ndc * p[3, 3] - p[2, 3]) / (ndc * p[3, 2] - p[2, 2])
        return np.where(window < 1.0, depth, np.inf)
