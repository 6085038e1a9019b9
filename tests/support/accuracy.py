"""Shared helpers for accuracy tests: render through the engine, evaluate the
float64 reference, compare (SPEC 1.5) and keep the pictures for a person."""

from __future__ import annotations

import numpy as np

from tests.support import reference, scenes

# Core thresholds of the exact path (image model §7, the specification's error measure).
P999_LIMIT = 2.0 / 255.0
MAX_LIMIT = 0.1


def measure(scene, name: str, output_dir, *, wire_alpha: float = 1.0) -> dict:
    """Render ``scene`` to PNG through the engine and compare its alpha
    (= wire alpha * I on a transparent film) with the reference."""
    rgba = scenes.render_to_file(scene, output_dir / f"{name}.png")
    ref = reference.render_reference(scene)
    measured = rgba[..., 3] / wire_alpha
    report = reference.error_report(measured, ref)
    save_error_image(output_dir / f"{name}_error.png", np.abs(measured - ref.intensity), ref.on_silhouette)
    report["name"] = name
    return report


def save_error_image(path, diff, on_silhouette):
    """|dI| as a heat map (red = error, blue = silhouette samples), for eyes."""
    import bpy

    h, w = diff.shape
    img = np.zeros((h, w, 4), np.float32)
    img[..., 0] = np.clip(diff * 10.0, 0, 1)
    img[..., 2] = on_silhouette * 0.5
    img[..., 3] = 1.0
    image = bpy.data.images.new("sw_error", w, h, alpha=True, float_buffer=False)
    image.pixels.foreach_set(img.ravel())
    image.filepath_raw = str(path)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def assert_accurate(report: dict) -> None:
    assert report["nan"] == 0, report
    assert report["p999"] <= P999_LIMIT, report
    assert report["max"] <= MAX_LIMIT, report
