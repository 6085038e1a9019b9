"""Differences between the Blender versions SolidWire supports, in one place.

Supported: Blender 4.2 LTS (``blender_version_min`` in the manifest) to 5.x;
``scripts/compat.sh`` runs the test suite on bpy 4.2 and 4.5 LTS from PyPI.
Everything that is not in all of them goes through a helper here, so a
caller never tests versions or attributes itself.

Known differences:

* ``gpu.types.GPUShaderCreateInfo.depth_write`` (declares how a fragment
  shader writes ``gl_FragDepth``) does not exist in 4.2; without the
  declaration GLSL may still write the depth, only the early-depth-test hint
  is lost.
* ``ImageFormatSettings.media_type`` (the image/video/multilayer family that
  must be chosen before ``file_format``) is new in Blender 5.0.
* A scene's compositor node group: ``Scene.compositing_node_group`` from
  5.0; from 5.3 a scene holds a list of compositor effects, each with its
  node group (``Scene.compositor_effects``), and the old property, which
  now reads and sets the active effect's group, is deprecated (to be
  removed in 6.0).
"""

from __future__ import annotations


def depth_write(info, mode: str = "ANY") -> bool:
    """``info.depth_write(mode)`` where Blender has it; False where it does not."""
    method = getattr(info, "depth_write", None)
    if method is None:
        return False
    method(mode)
    return True


def set_media_type(image_settings, media_type: str) -> bool:
    """Choose the output family (Blender 5) before setting ``file_format``;
    a no-op (False) before 5.0, where ``file_format`` alone decides."""
    if not hasattr(image_settings, "media_type"):
        return False
    image_settings.media_type = media_type
    return True


def has_compositor_node_group(scene) -> bool:
    """Whether ``scene`` takes a compositor node group (Blender 5.0 on)."""
    return hasattr(scene, "compositor_effects") or hasattr(scene, "compositing_node_group")


def set_compositor_node_group(scene, tree) -> None:
    """Composite ``scene`` with node group ``tree``: as its active compositor
    effect where scenes have effects (made if it has none), else as its
    compositor node group."""
    effects = getattr(scene, "compositor_effects", None)
    if effects is None:
        scene.compositing_node_group = tree
        return
    effect = effects.active or effects.new(name=tree.name)
    effect.node_group = tree
