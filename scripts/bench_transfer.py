"""Pixel transfer micro-benchmark: numpy -> RenderPass and GPU texture -> numpy.

    .venv/bin/python -m scripts.bench_transfer [--sizes 1280x720,3840x2160]
        [--repeats 5] [--verify] [--skip-slow]

Part 1 renders with a tiny throwaway engine (``bpy.ops.render.render``) whose
render() writes a random (H*W, 4) Combined and (H*W, 1) Depth array into
``begin_result``'s passes with each method and times that write only (the
file-based methods include writing their file). ``--verify`` then saves the
render to an uncompressed multilayer float EXR and checks that both passes hold
exactly the written bits. Part 2 times reading an RGBA32F and an R32F texture
back to numpy. Prints the median of ``--repeats`` runs in ms.
"""

from __future__ import annotations

import argparse
import os
import statistics
import struct
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="solidwire-user-"))

import bpy
import numpy as np

import solidwire_addon
from solidwire_addon.blender import engine
from solidwire_addon.blender.gpu_context import ensure_gpu
from solidwire_addon.core import exr, targets
from tests.support import scenes

TMP = Path(tempfile.mkdtemp(prefix="swxfer-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None))


# -- a minimal uncompressed scanline OpenEXR writer (for the load_from_file paths)


def write_exr(path: Path, channels: dict[str, np.ndarray]) -> None:
    """``channels``: name -> (H, W) float32, bottom row first (Blender's order)."""
    names = sorted(channels)
    height, width = channels[names[0]].shape
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for n in names) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)

    def attr(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    header = (
        b"\x76\x2f\x31\x01"
        + struct.pack("<I", 2)
        + attr("channels", "chlist", chlist)
        + attr("compression", "compression", b"\0")
        + attr("dataWindow", "box2i", box)
        + attr("displayWindow", "box2i", box)
        + attr("lineOrder", "lineOrder", b"\0")
        + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
        + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
        + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
        + b"\0"
    )
    line_bytes = 8 + 4 * width * len(names)
    start = len(header) + 8 * height
    offsets = (start + line_bytes * np.arange(height, dtype=np.uint64)).astype("<u8")
    lines = np.empty((height, 2 + width * len(names)), dtype="<f4")
    ints = lines.view("<i4")
    ints[:, 0] = np.arange(height)  # file row y (top first)
    ints[:, 1] = 4 * width * len(names)
    for k, name in enumerate(names):
        lines[:, 2 + k * width : 2 + (k + 1) * width] = channels[name][::-1]
    with open(path, "wb") as f:
        f.write(header)
        f.write(offsets.tobytes())
        f.write(lines.tobytes())


# -- write methods: (render_result, layer, rgba (N, 4), depth (N, 1)) -> None


def w_rect_assign(result, layer, rgba, depth):
    layer.passes["Combined"].rect = rgba
    layer.passes["Depth"].rect = depth


def w_foreach_set(result, layer, rgba, depth):
    layer.passes["Combined"].rect.foreach_set(rgba.ravel())
    layer.passes["Depth"].rect.foreach_set(depth.ravel())


def w_engine_write_pass(result, layer, rgba, depth):
    engine.write_pass(layer.passes["Combined"], rgba)
    engine.write_pass(layer.passes["Depth"], depth)


def _planes(rgba, depth, height, width, prefix):
    planes = {f"{prefix}Combined.{c}": rgba[:, i].reshape(height, width) for i, c in enumerate("RGBA")}
    planes[f"{prefix}Depth.Z"] = depth[:, 0].reshape(height, width)
    return planes


def w_result_load_exr(result, layer, rgba, depth):
    path = TMP / "result.exr"
    write_exr(path, _planes(rgba, depth, result.resolution_y, result.resolution_x, f"{layer.name}."))
    result.load_from_file(str(path))


def w_layer_load_exr(result, layer, rgba, depth):
    # bpy 5.0 reads the file as a render result (channels "<layer>.<pass>.<c>"
    # or "<pass>.<c>", every pass of the layer); 4.x read a plain RGBA image
    # into Combined only.
    path = TMP / "layer.exr"
    write_exr(path, _planes(rgba, depth, result.resolution_y, result.resolution_x, ""))
    layer.load_from_file(str(path))


WRITERS = {
    "rect = array (baseline)": w_rect_assign,
    "rect.foreach_set(ravel)": w_foreach_set,
    "engine.write_pass": w_engine_write_pass,
    "RenderResult.load_from_file (EXR in /dev/shm)": w_result_load_exr,
    "RenderLayer.load_from_file (EXR in /dev/shm)": w_layer_load_exr,
}
SLOW = {"rect = array (baseline)"}

_job = {}


class TransferEngine(bpy.types.RenderEngine):
    bl_idname = "SWXFER_BENCH"
    bl_label = "Transfer bench"
    bl_use_preview = False

    def render(self, depsgraph):
        width, height = _job["size"]
        result = self.begin_result(0, 0, width, height)
        layer = result.layers[0]
        start = time.perf_counter()
        _job["writer"](result, layer, _job["rgba"], _job["depth"])
        _job["ms"] = (time.perf_counter() - start) * 1000.0
        self.end_result(result)

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        self.register_pass(scene, renderlayer, "Depth", 1, "Z", "VALUE")


def bench_scene(width, height):
    scene = bpy.data.scenes.new("swxfer")
    scene.render.engine = TransferEngine.bl_idname
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_layers[0].use_pass_z = True
    cam_data = bpy.data.cameras.new("swxfer")
    cam = bpy.data.objects.new("swxfer", cam_data)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def verify(scene, rgba, depth):
    """Bit-exact check of both passes through a float multilayer EXR."""
    channels = scenes.render_multilayer_exr(scene, TMP / "verify.exr")
    layer = scene.view_layers[0].name
    got_rgba = exr.exr_pass(channels, layer, "Combined", "RGBA").reshape(-1, 4)
    got_depth = exr.exr_pass(channels, layer, "Depth", "Z").reshape(-1, 1)
    (TMP / "verify.exr").unlink()
    return np.array_equal(got_rgba.view(np.uint32), rgba.view(np.uint32)) and np.array_equal(
        got_depth.view(np.uint32), depth.view(np.uint32)
    )


def bench_writes(sizes, repeats, do_verify, skip_slow):
    rng = np.random.default_rng(1)
    rows = []
    for width, height in sizes:
        scene = bench_scene(width, height)
        rgba = rng.random((width * height, 4), dtype=np.float32)
        depth = (rng.random((width * height, 1), dtype=np.float32) * 100.0).astype(np.float32)
        _job.update(size=(width, height), rgba=rgba, depth=depth)
        for name, writer in WRITERS.items():
            if skip_slow and name in SLOW:
                continue
            _job["writer"] = writer
            times = []
            try:
                for _ in range(repeats):
                    bpy.ops.render.render(scene=scene.name)
                    times.append(_job.pop("ms"))
                ok = verify(scene, rgba, depth) if do_verify else None
                rows.append((name, f"{width}x{height}", statistics.median(times), ok))
            except Exception as exc:  # noqa: BLE001  (a method the running Blender lacks: a row, not a crash)
                rows.append((name, f"{width}x{height}", float("nan"), f"{type(exc).__name__}: {exc}"))
        bpy.data.scenes.remove(scene)
    return rows


# -- readback methods: texture -> (H, W, C) float32


def r_read_array(texture, channels):  # the original _read_texture
    buf = texture.read()
    buf.dimensions = texture.width * texture.height * channels
    return np.array(buf, dtype=np.float32).reshape(texture.height, texture.width, channels)


def r_read_frombuffer(texture, channels):
    buf = texture.read()
    buf.dimensions = texture.width * texture.height * channels
    return np.frombuffer(buf, dtype=np.float32).reshape(texture.height, texture.width, channels)


def r_read_tolist(texture, channels):  # no flatten: what the stride bug forces without it
    return np.array(texture.read().to_list(), dtype=np.float32)


def make_fb_reader(framebuffer, slot):
    def r_read_color(texture, channels):
        import gpu

        buf = gpu.types.Buffer("FLOAT", texture.width * texture.height * channels)
        with framebuffer.bind():
            framebuffer.read_color(0, 0, texture.width, texture.height, channels, slot, "FLOAT", data=buf)
        return np.frombuffer(buf, dtype=np.float32).reshape(texture.height, texture.width, channels)

    return r_read_color


def bench_reads(sizes, repeats, skip_slow):
    import gpu

    ensure_gpu()
    rng = np.random.default_rng(2)
    rows = []
    for width, height in sizes:
        data = {4: rng.random(width * height * 4, dtype=np.float32), 1: rng.random(width * height, dtype=np.float32)}
        color = gpu.types.GPUTexture(
            (width, height), format="RGBA32F", data=gpu.types.Buffer("FLOAT", data[4].size, data[4])
        )
        mono = gpu.types.GPUTexture(
            (width, height), format="R32F", data=gpu.types.Buffer("FLOAT", data[1].size, data[1])
        )
        fb = gpu.types.GPUFrameBuffer(color_slots=(color, mono))
        readers = {
            "texture.read -> np.array (baseline)": r_read_array,
            "texture.read -> np.frombuffer": r_read_frombuffer,
            "targets.read_texture": targets.read_texture,
            "framebuffer.read_color(data=Buffer) -> frombuffer": None,
        }
        if not skip_slow:
            readers["texture.read().to_list() (no flatten)"] = r_read_tolist
        for name, reader in readers.items():
            for channels, texture, slot in ((4, color, 0), (1, mono, 1)):
                fn = reader or make_fb_reader(fb, slot)
                times = []
                for _ in range(repeats):
                    start = time.perf_counter()
                    out = fn(texture, channels)
                    times.append((time.perf_counter() - start) * 1000.0)
                ok = np.array_equal(
                    np.asarray(out, dtype=np.float32).ravel().view(np.uint32), data[channels].view(np.uint32)
                )
                rows.append(
                    (
                        f"{name} [{'RGBA32F' if channels == 4 else 'R32F'}]",
                        f"{width}x{height}",
                        statistics.median(times),
                        ok,
                    )
                )
        del fb, color, mono
    return rows


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--sizes", default="1280x720,3840x2160")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--verify", action="store_true", help="bit-exact check of every write method via EXR")
    parser.add_argument("--skip-slow", action="store_true", help="skip the baseline rect assignment and to_list")
    parser.add_argument("--only", choices=("write", "read"))
    args = parser.parse_args()
    sizes = [tuple(int(v) for v in s.split("x")) for s in args.sizes.split(",")]
    solidwire_addon.register()
    bpy.utils.register_class(TransferEngine)
    try:
        rows = []
        if args.only != "read":
            rows += bench_writes(sizes, args.repeats, args.verify, args.skip_slow)
        if args.only != "write":
            rows += bench_reads(sizes, args.repeats, args.skip_slow)
    finally:
        bpy.utils.unregister_class(TransferEngine)
        solidwire_addon.unregister()
        for f in TMP.glob("*"):
            f.unlink()
        TMP.rmdir()
    print(f"\nbpy {bpy.app.version_string}, numpy {np.__version__}, median of {args.repeats}")
    print(f"{'method':58s} {'size':>10s} {'ms':>9s}  exact")
    for name, size, ms, ok in rows:
        print(f"{name:58s} {size:>10s} {ms:9.1f}  {'-' if ok is None else ok}")


if __name__ == "__main__":
    main()
