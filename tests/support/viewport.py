"""Blender's real 3D viewport, drawn headless, with SolidWire's overlay on top.

``GPUOffScreen.draw_view3d`` draws a 3D View of the startup file's screens
(Solid shading, Blender's overlays, colour management) into an offscreen
once the GPU is usable. It never calls Python draw handlers, so SolidWire's
overlay is drawn into the same offscreen afterwards with
``overlay.draw_scene_overlay``, as the POST_VIEW handler would draw it: over
the colour and the depth Blender left there.

Used by tests/test_viewport_headless.py and scripts/bench_viewport.py.
"""

from __future__ import annotations

import bpy
import gpu
import numpy as np
from mathutils import Matrix

from solidwire_addon.blender import overlay
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core.view import View

# The object types whose surfaces Solid shading draws into the depth.
SURFACE_TYPES = ("MESH", "CURVE", "FONT", "SURFACE", "META")


def draw_scene_depth(framebuffer, size, depsgraph, view: View, objects) -> None:
    """Into ``framebuffer``, the depth Blender's Solid shading leaves for
    ``objects`` and their instances (_surfaces; others, and meshes without
    triangles, are skipped): object-space float32 positions through a
    float32 model-view-projection, no re-centring, no float64. The overlay plans
    Solid shading with Blender's depth holding every surface it draws, so a
    test of that mode draws this first."""
    from gpu_extras.batch import batch_for_shader

    shader = gpu.shader.from_builtin("UNIFORM_COLOR")
    view_matrix = Matrix(view.view_matrix.tolist())
    projection = Matrix(view.projection.tolist())
    with framebuffer.bind():
        gpu.state.viewport_set(0, 0, *size)
        gpu.state.depth_test_set("LESS_EQUAL")
        gpu.state.depth_mask_set(True)
        gpu.state.color_mask_set(False, False, False, False)
        with gpu.matrix.push_pop(), gpu.matrix.push_pop_projection():
            gpu.matrix.load_projection_matrix(projection)
            for coords, tris, matrix in _surfaces(depsgraph, objects):
                batch = batch_for_shader(shader, "TRIS", {"pos": coords.reshape(-1, 3)}, indices=tris.reshape(-1, 3))
                gpu.matrix.load_matrix(view_matrix @ matrix)
                shader.bind()
                shader.uniform_float("color", (0.5, 0.5, 0.5, 1.0))
                batch.draw(shader)
        gpu.state.color_mask_set(True, True, True, True)
        gpu.state.depth_test_set("NONE")
        gpu.state.depth_mask_set(False)


def _surfaces(depsgraph, objects) -> list:
    """(float32 positions, triangle corners, object -> world) of every
    surface Solid shading draws for ``objects``: their own evaluated
    geometry and the instances they make (a collection instance, geometry
    nodes). Text, curves, surfaces and metaballs give their tessellation,
    which Solid shading draws as it draws a mesh."""
    names = {obj.name for obj in objects}
    surfaces = []
    for instance in depsgraph.object_instances:
        owner = instance.parent if instance.is_instance and instance.parent is not None else instance.object
        if owner.original.name not in names or not (instance.is_instance or instance.show_self):
            continue
        obj_eval = instance.object
        if obj_eval.type not in SURFACE_TYPES:
            continue
        matrix = Matrix(instance.matrix_world)  # (a copy: the instance is gone after this step)
        mesh = obj_eval.to_mesh()
        try:
            mesh.calc_loop_triangles()
            coords = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
            mesh.vertices.foreach_get("co", coords)
            tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
            mesh.loop_triangles.foreach_get("vertices", tris)
        finally:
            obj_eval.to_mesh_clear()
        if len(tris):
            surfaces.append((coords, tris, matrix))
    return surfaces


class ViewportUnavailable(RuntimeError):
    """This Blender cannot draw its viewport headless (no draw_view3d, no
    3D View in the startup screens, or the call fails)."""


def view3d(screen_name: str = "Layout"):
    """(space, WINDOW region) of the first 3D View of a startup screen."""
    screen = bpy.data.screens.get(screen_name)
    if screen is None:
        raise ViewportUnavailable(f"no screen named {screen_name!r} (a file read with use_empty screens?)")
    for area in screen.areas:
        if area.type == "VIEW_3D":
            for region in area.regions:
                if region.type == "WINDOW":
                    return area.spaces.active, region
    raise ViewportUnavailable(f"screen {screen_name!r} has no 3D View")


class HeadlessViewport:
    """One W x H offscreen that Blender's viewport and SolidWire's overlay
    draw into. The view comes from the scene camera at the offscreen's size
    (the region's own matrices are made for the region's size, not ours);
    the camera object is hidden in the viewport so that Blender does not draw
    it as an overlay."""

    def __init__(self, width: int, height: int, screen_name: str = "Layout"):
        ensure_gpu()
        if not hasattr(gpu.types.GPUOffScreen, "draw_view3d"):
            raise ViewportUnavailable("gpu.types.GPUOffScreen has no draw_view3d")
        self.size = (width, height)
        self.space, self.region = view3d(screen_name)
        self.offscreen = gpu.types.GPUOffScreen(width, height)
        self.view: View | None = None
        # A 3D View that looks through the camera would use the camera's
        # own frame, not the matrices given here.
        self.space.region_3d.view_perspective = "PERSP"

    def free(self) -> None:
        self.offscreen.free()

    def look_through(self, scene, depsgraph=None) -> View:
        """Take the scene camera's view for the offscreen size; hide the
        camera object in the viewport."""
        depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
        self.view = camera_view(scene, depsgraph, self.size)
        scene.camera.hide_set(True)
        return self.view

    # -- drawing ----------------------------------------------------------------

    def draw_blender(self, scene=None, view_layer=None) -> None:
        """Blender's viewport (shading and overlays as the 3D View's settings
        say), colour-managed, into the offscreen (colour and depth). The
        depsgraph is evaluated first (a no-op when nothing changed): the
        window manager does that before a redraw, draw_view3d does not."""
        scene = scene or bpy.context.scene
        view_layer = view_layer or bpy.context.view_layer
        view_layer.depsgraph.update()
        try:
            self.offscreen.draw_view3d(
                scene,
                view_layer,
                self.space,
                self.region,
                Matrix(self.view.view_matrix.tolist()),
                Matrix(self.view.projection.tolist()),
                do_color_management=True,
            )
        except (RuntimeError, SystemError, TypeError) as exc:
            raise ViewportUnavailable(f"draw_view3d failed: {exc}") from exc

    def draw_solidwire(self, depsgraph=None, settings=None, **kwargs) -> dict:
        """SolidWire's overlay over what the offscreen holds (its depth hides
        wires behind Blender's surfaces), as the POST_VIEW handler draws it.
        Returns the frame stats."""
        depsgraph = depsgraph or bpy.context.evaluated_depsgraph_get()
        if settings is None:
            settings = depsgraph.scene.solidwire.snapshot()
        with self.offscreen.bind():
            gpu.state.viewport_set(0, 0, *self.size)
            return overlay.draw_scene_overlay(depsgraph, self.view, settings, **kwargs)

    def sync(self) -> None:
        """Wait until the GPU has finished every draw into the offscreen (a
        one-pixel read waits for them)."""
        with self.offscreen.bind():
            gpu.state.active_framebuffer_get().read_color(0, 0, 1, 1, 4, 0, "UBYTE")

    def rgba(self) -> np.ndarray:
        """(H, W, 4) uint8 as the screen shows it (display-encoded), bottom
        row first."""
        buffer = self.offscreen.texture_color.read()
        width, height = self.size
        buffer.dimensions = width * height * 4
        return np.asarray(buffer, dtype=np.uint8).reshape(height, width, 4)


def set_overlays(space, *, overlays: bool = True, wireframe: bool = False) -> None:
    """Blender's overlays on or off, and its Wireframe overlay showing every
    edge at full opacity (threshold 1, opacity 1) when ``wireframe``."""
    space.overlay.show_overlays = overlays
    space.overlay.show_wireframes = wireframe
    space.overlay.wireframe_threshold = 1.0
    space.overlay.wireframe_opacity = 1.0
