"""Blender's bundled matcaps (``datafiles/studiolights/matcap/NAME.exr``)
read as pixels for core/matcaps.py (the MATCAP fill, docs/image_model.md §5.8).

Most bundled matcaps are multilayer EXR files with a ``diffuse`` and a
``specular`` pass (DWAA-compressed), which ``Image.pixels`` cannot read. Each
pass is therefore taken through Blender's compositor: a tiny scratch scene
renders the Image node's pass into an uncompressed float EXR that
core/exr.py reads. Everything made for it (scene, node group, image, file)
is removed again; nothing stays in the user's file.

A render cannot be started from a render or from drawing, so in Blender's
interface a matcap is decoded ahead of use, in the main thread from a timer:
when Shading or MatCap changes in the panel, and when a file whose scenes use
a matcap is loaded. Until then a draw gets ``matcaps.PENDING`` (a flat fill,
one message). Without an interface (the bpy module, ``blender -b``) a render
runs in the main thread and decodes on first use.
"""

from __future__ import annotations

import os
import tempfile
import threading

import bpy
import numpy as np
from bpy.app.handlers import persistent

from ..core import compat, exr, matcaps, shaders
from . import runtime

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
    images_before = set(bpy.data.images)
    try:
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        node = tree.nodes.new("CompositorNodeImage")
        node.image = image
        out = tree.nodes.new("NodeGroupOutput")
        compat.set_compositor_node_group(scene, tree)
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
        # A process's first render makes the "Render Result" image; this
        # decode is not a render the user asked for, so it leaves none.
        for made in set(bpy.data.images) - images_before:
            if made.type == "RENDER_RESULT":
                bpy.data.images.remove(made)
    return result


def _multilayer_size(image) -> tuple[int, int]:
    """The data window of an EXR file (Blender reports (0, 0) for multilayer
    images until an image user has loaded them)."""
    import struct

    with open(bpy.path.abspath(image.filepath), "rb") as file:
        data = file.read(1 << 16)
    marker = data.index(b"dataWindow\0box2i\0")
    x0, y0, x1, y1 = struct.unpack_from("<4i", data, marker + len("dataWindow\0box2i\0") + 4)
    return x1 - x0 + 1, y1 - y0 + 1


_decoded: dict[str, object] = {}


def load_pixels(name: str):
    """The loader of core/matcaps.py: decoded pixels, None (no such file) or
    matcaps.PENDING (asked for; decoded soon in the main thread)."""
    if name in _decoded:
        return _decoded[name]
    if _can_decode_now():
        return _decode_once(name)
    if threading.current_thread() is threading.main_thread():
        request(name)
    return matcaps.PENDING


def _can_decode_now() -> bool:
    """Decoding renders a scratch scene, so never inside a render (a render
    started from a render deadlocks Blender 5.3) nor off the main thread;
    in a UI session it waits for a timer (outside any draw)."""
    return (
        bpy.app.background
        and threading.current_thread() is threading.main_thread()
        and not shaders.in_render_engine_context()
    )


def prepare(name: str) -> None:
    """Decode matcap ``name`` before it is needed: now when that is safe
    (background, main thread, not rendering), else soon in the main thread.
    Called when the matcap or the shading is chosen and when a file opens."""
    if name in _decoded:
        return
    if _can_decode_now():
        try:
            _decode_once(name)
        except Exception as exc:  # noqa: BLE001 - an update callback must not raise
            print(f"SolidWire: matcap '{name}' could not be read ({exc})")
            _decoded[name] = None
        matcaps.forget(name)
    else:
        request(name)


def request(name: str) -> None:
    """Decode matcap ``name`` soon, in the main thread, outside any draw."""
    if name in _decoded or name in _requested:
        return
    _requested.add(name)

    def decode():
        _requested.discard(name)
        try:
            _decode_once(name)
        except Exception as exc:  # noqa: BLE001 - a timer must not raise
            print(f"SolidWire: matcap '{name}' could not be read ({exc})")
            _decoded[name] = None
        matcaps.forget(name)
        runtime.redraw_viewports()

    bpy.app.timers.register(decode, first_interval=0.0)


_requested: set[str] = set()


def _decode_once(name: str):
    if name not in _decoded:
        _decoded[name] = decode_pixels(name)
    return _decoded[name]


def decode_pixels(name: str):
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


def request_for_scenes(*_args) -> None:
    """Decode the matcaps that the open file's scenes use (after a load)."""
    for scene in bpy.data.scenes:
        props = getattr(scene, "solidwire", None)
        if props is not None and props.use_fill and props.fill_shading == "MATCAP":
            prepare(props.matcap)


_on_load = persistent(request_for_scenes)


def register() -> None:
    matcaps.set_loader(load_pixels)
    if not bpy.app.background:
        bpy.app.handlers.load_post.append(_on_load)


def unregister() -> None:
    matcaps.set_loader(None)
    if _on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load)
    _requested.clear()
