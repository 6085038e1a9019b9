"""Views from Blender cameras and viewports, as float64 numpy matrices."""

from __future__ import annotations

import numpy as np

from ..core.view import View, affine_inverse


class NoCameraError(ValueError):
    pass


def render_size(scene) -> tuple[int, int]:
    """Final render size in pixels after the resolution percentage."""
    r = scene.render
    scale = r.resolution_percentage / 100.0
    return max(int(r.resolution_x * scale), 1), max(int(r.resolution_y * scale), 1)


def refuse_unsupported(scene, camera) -> None:
    """NoCameraError naming what a render cannot draw: a panoramic camera
    (its projection is no matrix, and calc_matrix_camera would quietly give
    a perspective one) or stereo/multiview output (one image per view is
    not rendered: every view would get the same picture)."""
    data = camera.data if camera.type == "CAMERA" else None
    if data is not None and data.type == "PANO":
        kind = _enum_name(data, "panorama_type")
        raise NoCameraError(
            f"camera '{camera.name}' is a panoramic camera ({kind}); SolidWire renders perspective and "
            "orthographic cameras only"
        )
    if scene.render.use_multiview:
        raise NoCameraError(
            f"scene '{scene.name}' has Stereoscopy (multiview) on; SolidWire renders one view only "
            "(Output Properties > Stereoscopy)"
        )


def _enum_name(data, prop: str) -> str:
    """The UI name of an enum property's current value (its identifier if
    Blender has no name for it)."""
    value = getattr(data, prop, "")
    try:
        return data.bl_rna.properties[prop].enum_items[value].name
    except (KeyError, AttributeError):
        return str(value)


def camera_view(scene, depsgraph, size: tuple[int, int] | None = None) -> View:
    """The scene camera's view exactly as Blender projects it (docs/image_model.md §1).

    Perspective and orthographic cameras, lens shift, sensor fit and pixel
    aspect all come from ``calc_matrix_camera``. The camera's scale is
    ignored, as in Blender's renderers."""
    camera = scene.camera
    if camera is None:
        raise NoCameraError(f"scene '{scene.name}' has no camera")
    refuse_unsupported(scene, camera)
    camera = camera.evaluated_get(depsgraph)
    width, height = size or render_size(scene)
    r = scene.render
    projection = camera.calc_matrix_camera(
        depsgraph, x=width, y=height, scale_x=r.pixel_aspect_x, scale_y=r.pixel_aspect_y
    )
    # Scale is dropped by normalising the axes, as Blender's renderers do
    # (normalize_m4): a negatively scaled camera stays mirrored. (decompose()
    # would turn a mirror into a half turn and look the other way.)
    camera_to_world = np.array(camera.matrix_world, dtype=np.float64)
    axis_length = np.linalg.norm(camera_to_world[:3, :3], axis=0)
    if not (np.isfinite(camera_to_world).all() and (axis_length > 0.0).all()):
        raise NoCameraError(f"camera '{camera.name}' has a zero or non-finite scale or transform")
    camera_to_world[:3, :3] /= axis_length
    return View(affine_inverse(camera_to_world), np.array(projection, dtype=np.float64), (0, 0, width, height))


def region_view(region, region_3d) -> View:
    """A 3D viewport region's view (for the overlay)."""
    return View(
        np.array(region_3d.view_matrix, dtype=np.float64),
        np.array(region_3d.window_matrix, dtype=np.float64),
        (0, 0, region.width, region.height),
    )
