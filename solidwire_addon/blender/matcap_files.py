"""Blender's bundled matcaps (``datafiles/studiolights/matcap/NAME.exr``)
read as pixels for core/matcaps.py (the MATCAP fill, docs/image_model.md §5.8).

Most bundled matcaps are multilayer EXR files with a ``diffuse`` and a
``specular`` pass (DWAA-compressed), which ``Image.pixels`` cannot read. Each
pass is therefore taken through Blender's compositor: a tiny scratch scene
renders the Image node's pass into an uncompressed float EXR that
core/exr.py reads. Everything made for it (scene, node group, image, file)
is removed again; nothing stays in the user's file.
"""

from __future__ import annotations

import os
import tempfile

import bpy
import numpy as np

from ..core import exr, matcaps

SUBFOLDER = "studiolights/matcap"


def matcap_path(name: str) -> str | None:
    """The bundled file of matcap ``name``, or None."""
    folder = bpy.utils.system_resource("DATAFILES", path=SUBFOLDER)
    path = os.path.join(folder, name + ".exr") if folder else ""
    return path if path and os.path.isfile(path) else None


def _passes_through_compositor(image, outputs) -> dict:
    """{pass name: (H, W, 4) float32, bottom row first} for a multilayer image."""
    width, height = 0, 0
    scene = bpy.data.scenes.new("solidwire_matcap")
    tree = bpy.data.node_groups.new("solidwire_matcap", "CompositorNodeTree")
    result = {}
    try:
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        node = tree.nodes.new("CompositorNodeImage")
        node.image = image
        out = tree.nodes.new("NodeGroupOutput")
        scene.compositing_node_group = tree
        scene.render.use_compositing = True
        scene.render.film_transparent = True
        scene.render.engine = "BLENDER_WORKBENCH"
        settings = scene.render.image_settings
        settings.file_format = "OPEN_EXR"
        settings.exr_codec = "NONE"
        settings.color_depth = "32"
        settings.color_mode = "RGBA"
        with tempfile.TemporaryDirectory(prefix="solidwire-matcap-") as folder:
            for name in outputs:
                for link in list(tree.links):
                    tree.links.remove(link)
                tree.links.new(node.outputs[name], out.inputs[0])
                if not width:
                    # The compositor renders at the scene size: the image's own.
                    width, height = _multilayer_size(image)
                    scene.render.resolution_x, scene.render.resolution_y = width, height
                    scene.render.resolution_percentage = 100
                scene.render.filepath = os.path.join(folder, name + ".exr")
                bpy.ops.render.render(write_still=True, scene=scene.name)
                channels = exr.read_exr(scene.render.filepath)
                result[name] = np.stack([channels[c] for c in "RGBA"], axis=-1)
    finally:
        bpy.data.node_groups.remove(tree)
        bpy.data.scenes.remove(scene)
    return result


def _multilayer_size(image) -> tuple[int, int]:
    """The data window of an EXR file (Blender reports (0, 0) for multilayer
    images until an image user has loaded them)."""
    import struct

    data = open(bpy.path.abspath(image.filepath), "rb").read(1 << 16)
    marker = data.index(b"dataWindow\0box2i\0")
    x0, y0, x1, y1 = struct.unpack_from("<4i", data, marker + len("dataWindow\0box2i\0") + 4)
    return x1 - x0 + 1, y1 - y0 + 1


def load_pixels(name: str):
    """(diffuse, specular or None), each (H, W, 4) float32 bottom row first,
    or None when the file is missing."""
    path = matcap_path(name)
    if path is None:
        return None
    image = bpy.data.images.load(path, check_existing=False)
    try:
        width, height = image.size
        if width and height:
            pixels = np.empty(width * height * 4, dtype=np.float32)
            image.pixels.foreach_get(pixels)
            return pixels.reshape(height, width, 4), None
        passes = _passes_through_compositor(image, ("diffuse", "specular"))
        return passes["diffuse"], passes.get("specular")
    finally:
        bpy.data.images.remove(image)


def register() -> None:
    matcaps.set_loader(load_pixels)


def unregister() -> None:
    matcaps.set_loader(None)
