"""Property-based tests: random small meshes, cameras and
settings. Every example renders through the real engine to a float EXR and
must raise nothing, hold no NaN/Inf and agree with the float64 reference on
non-silhouette pixels (p99.9 <= 2/255, max <= 0.1).

Default CI runs a fixed, derandomised set of examples; a long random hunt:
``SOLIDWIRE_FUZZ_EXAMPLES=500 pytest tests/test_fuzz.py`` (make fuzz).
A failure prints the scene recipe (``repro``) to rebuild it by hand.
"""

from __future__ import annotations

import math
import os

import bpy
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from solidwire_addon.core import log
from tests.support import accuracy, reference, robustness, scenes

pytestmark = pytest.mark.fuzz

W, H = 48, 36
LONG_RUN = int(os.environ.get("SOLIDWIRE_FUZZ_EXAMPLES", "0") or 0)
FUZZ = settings(
    max_examples=LONG_RUN or 30,
    deadline=None,
    derandomize=not LONG_RUN,
    database=None if not LONG_RUN else settings.default.database,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture, HealthCheck.data_too_large],
    print_blob=True,
    # Shrinking a render takes minutes; the failing scene's recipe is printed.
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
)

coord = st.floats(-2.0, 2.0, allow_nan=False)
point = st.tuples(coord, coord, coord)


@st.composite
def polygons(draw):
    """A few triangles, quads and n-gons; some share vertices, some are far,
    nearly degenerate or (rarely) hold a NaN/Inf corner."""
    verts: list[tuple] = []
    faces: list[tuple] = []
    for _ in range(draw(st.integers(1, 4))):
        size = draw(st.sampled_from([3, 3, 4, 4, 4, 5, 6]))
        face = []
        for _corner in range(size):
            kind = draw(st.sampled_from(["new"] * 6 + ["shared", "near", "far", "bad"]))
            if kind == "shared" and verts:
                index = draw(st.integers(0, len(verts) - 1))
                if index in face:
                    kind = "new"
                else:
                    face.append(index)
                    continue
            if kind == "near" and face:
                base = verts[face[-1]]
                offset = draw(st.tuples(*[st.floats(-1e-3, 1e-3)] * 3))
                verts.append(tuple(b + o for b, o in zip(base, offset)))
            elif kind == "far":
                verts.append(tuple(draw(st.floats(-40.0, 40.0)) for _ in range(3)))
            elif kind == "bad":
                value = draw(st.sampled_from([math.nan, math.inf, -math.inf]))
                p = list(draw(point))
                p[draw(st.integers(0, 2))] = value
                verts.append(tuple(p))
            else:
                verts.append(draw(point))
            face.append(len(verts) - 1)
        faces.append(tuple(face))
    return verts, faces


@st.composite
def cameras(draw):
    distance = draw(st.floats(0.3, 12.0))
    azimuth = draw(st.floats(0.0, 360.0))
    elevation = draw(st.floats(-80.0, 80.0))
    target = draw(st.tuples(*[st.floats(-1.0, 1.0)] * 3))
    ortho = draw(st.booleans())
    return {
        "location": tuple(t + o for t, o in zip(target, scenes.orbit_location(distance, azimuth, elevation))),
        "target": target,
        "lens": draw(st.floats(12.0, 150.0)),
        "ortho_scale": draw(st.floats(1.0, 12.0)) if ortho else None,
        "shift": (draw(st.floats(-0.3, 0.3)), draw(st.floats(-0.3, 0.3))),
        "clip": (draw(st.sampled_from([0.01, 0.1, 0.5])), draw(st.sampled_from([20.0, 100.0]))),
        "sensor_fit": draw(st.sampled_from(["AUTO", "HORIZONTAL", "VERTICAL"])),
    }


@st.composite
def line_settings(draw):
    mode = draw(st.sampled_from(["HIDDEN", "SOLID", "DOTTED", "DASHED"]))
    values = {
        "thickness": draw(st.sampled_from([0.0, 0.5, 1.5, 3.0, 40.0, draw(st.floats(0.0, 8.0))])),
        "softness": draw(st.sampled_from([0.01, 0.25, 1.0, 2.5, 100.0, draw(st.floats(0.25, 4.0))])),
        "diagonal_mode": mode,
        "use_backface_culling": draw(st.booleans()),
        "use_fade": draw(st.booleans()),
        "fade_start": draw(st.floats(0.0, 10.0)),
        "fade_end": draw(st.floats(0.0, 15.0)),
    }
    if mode in ("DOTTED", "DASHED"):
        values["pattern_period"] = draw(st.floats(1.0, 20.0))
        values["pattern_duty"] = draw(st.sampled_from([0.0, 0.25, 0.5, 1.0, draw(st.floats(0.0, 1.0))]))
    return values


@st.composite
def transforms(draw):
    sign = draw(st.sampled_from([(1, 1, 1), (1, 1, 1), (-1, 1, 1), (1, -1, -1)]))
    scale = tuple(s * draw(st.floats(0.3, 2.0)) for s in sign)
    rotation = tuple(draw(st.floats(-math.pi, math.pi)) for _ in range(3))
    return {
        "rotation": rotation,
        "scale": scale,
        "location": draw(st.tuples(*[st.floats(-0.5, 0.5)] * 3)),
        "pixel_aspect": draw(st.sampled_from([1.0, 1.0, 1.0, 2.0])),
    }


def build(mesh, camera, line, transform):
    # diagonal_mode's update resets the duty: set the mode first.
    line = dict(line)
    duty = line.pop("pattern_duty", None)
    scene = scenes.empty_scene(W, H, **line)
    if duty is not None:
        scene.solidwire.pattern_duty = duty
    scene.render.pixel_aspect_x = transform.get("pixel_aspect", 1.0)
    verts, faces = mesh
    data = bpy.data.meshes.new("Fuzz")
    data.from_pydata(verts, [], faces)
    data.update()
    obj = bpy.data.objects.new("Fuzz", data)
    scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler, obj.scale = transform["location"], transform["rotation"], transform["scale"]
    scenes.add_camera(scene, **camera)
    return scene


def repro(mesh, camera, line, transform) -> str:
    return f"mesh={mesh!r}\ncamera={camera!r}\nsettings={line!r}\ntransform={transform!r}"


def check(scene, path):
    image = robustness.render_exr(scene, path)
    assert np.isfinite(image).all(), "NaN/Inf pixels"
    ref = reference.render_reference(scene)
    report = reference.error_report(image[..., 3].astype(np.float64), ref)
    accuracy.assert_accurate(report)
    return report


@FUZZ
@given(mesh=polygons(), camera=cameras(), line=line_settings(), transform=transforms())
def test_random_scenes_match_reference(mesh, camera, line, transform, tmp_path_factory):
    check_example(mesh, camera, line, transform, tmp_path_factory.getbasetemp() / "fuzz.exr")


def check_example(mesh, camera, line, transform, path):
    """Build, render and compare one example; print its recipe when it fails."""
    log.forget()
    scene = build(mesh, camera, line, transform)
    try:
        check(scene, path)
    except Exception:
        print("\n--- fuzz scene ---\n" + repro(mesh, camera, line, transform))
        raise


@st.composite
def edge_settings(draw):
    """Line settings plus the edge selection (image model §3.4-§3.7): edge
    angle (regions), the boundary class and the density fade."""
    values = draw(line_settings())
    values["edge_angle"] = draw(st.sampled_from([0.0, 0.2, 1.0, 3.0, draw(st.floats(0.0, math.pi))]))
    if draw(st.booleans()):
        values["use_boundary_edges"] = True
        values["boundary_thickness"] = draw(st.sampled_from([0.0, 2.0, draw(st.floats(0.0, 6.0))]))
        values["boundary_pattern"] = draw(st.sampled_from(["SOLID", "DOTTED", "DASHED"]))
    if draw(st.booleans()):
        values["use_density_fade"] = True
        values["density_fade_length"] = draw(st.sampled_from([0.0, 4.0, draw(st.floats(0.0, 40.0))]))
    return values


@FUZZ
@given(mesh=polygons(), camera=cameras(), line=edge_settings(), transform=transforms())
def test_random_edge_selections_match_reference(mesh, camera, line, transform, tmp_path_factory):
    check_example(mesh, camera, line, transform, tmp_path_factory.getbasetemp() / "fuzz_edges.exr")
