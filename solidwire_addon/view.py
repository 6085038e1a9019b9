"""Views from Blender cameras and viewports, as float64 numpy matrices."""

from __future__ import annotations

import numpy as np

from .draw import View


class NoCameraError(ValueError):
    pass


def render_size(scene) -> tuple[int, int]:
    """Final render size in pixels after the resolution percentage."""
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(int(r.resolution_x * scale), 1), max(int(r.resolution_y * scale), 1)


def camera_view(scene, depsgraph, size: tuple[int, int] | None = None) -> View:
    """The scene camera's view exactly as Blender projects it (SPEC 1.1).

    Perspective and orthographic cameras, lens shift, sensor fit and pixel
    aspect all come from ``calc_matrix_camera``. The camera's scale is
    ignored, as in Blender's renderers."""
    from mathutils import Matrix

    camera = scene.camera
    if camera is None:
        raise NoCameraError(f"scene '{scene.name}' has no camera")
    camera = camera.evaluated_get(depsgraph)
    width, height = size or render_size(scene)
    r = scene.render
    projection = camera.calc_matrix_camera(
        depsgraph, x=width, y=height, scale_x=r.pixel_aspect_x, scale_y=r.pixel_aspect_y
    )
    location, rotation, _scale = camera.matrix_world.decompose()
    camera_to_world = np.array(Matrix.LocRotScale(location, rotation, None), dtype=np.float64)
    return View(np.linalg.inv(camera_to_world), np.array(projection, dtype=np.float64), (0, 0, width, height))


def region_view(region, region_3d) -> View:
    """A 3D viewport region's view (for the overlay)."""
    return View(
        np.array(region_3d.view_matrix, dtype=np.float64),
        np.array(region_3d.window_matrix, dtype=np.float64),
        (0, 0, region.width, region.height),
    )
