"""Property-based tests: random small meshes, cameras and settings, random
modifier stacks under cage edges, hair and point clouds, and text, curves,
surfaces and metaballs. Every example renders through the real engine to a
float EXR (most also through the viewport overlay) and must raise nothing,
hold no NaN/Inf and agree with the float64 reference on non-silhouette
pixels (p99.9 <= 2/255, max <= 0.1); drags of the stacks' vertices in the
overlay must end on what a fresh frame draws. docs/dev/robustness.md (Fuzzing)
says what each set draws and what its hunts found.

Default CI runs a fixed, derandomised set of examples; a long random hunt:
``SOLIDWIRE_FUZZ_EXAMPLES=500 pytest tests/test_fuzz.py`` (make fuzz).
A failure prints the scene recipe (``repro``) to rebuild it by hand.
"""

from __future__ import annotations

import importlib
import math
import os
import pkgutil
from contextlib import contextmanager

import bpy
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, example, given, settings
from hypothesis import strategies as st
from mathutils import Matrix, Vector

from solidwire_addon.core import log
from tests.support import accuracy, reference, robustness, scenes, strand_reference, strand_scenes

pytestmark = pytest.mark.fuzz


def _load_every_project_module() -> None:
    """Import every module of the project. Hypothesis mixes the literal
    constants of the local modules loaded so far into what it draws, so a
    derandomised example depends on which modules the tests that ran
    before happened to import (the order is random): with all of them
    loaded first, every run and every machine draws the same examples, and
    a CI failure replays here."""
    for package in ("solidwire_addon", "scripts", "tests", "tests.pure"):
        for module in pkgutil.iter_modules(importlib.import_module(package).__path__, f"{package}."):
            if not module.name.endswith("conftest"):
                importlib.import_module(module.name)
                if module.ispkg:
                    for inner in pkgutil.walk_packages(
                        importlib.import_module(module.name).__path__, f"{module.name}."
                    ):
                        importlib.import_module(inner.name)


_load_every_project_module()

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
    """A few triangles, quads and n-gons; some share vertices, some have
    vertices at others' positions, some are far, nearly degenerate or
    (rarely) hold a NaN/Inf corner."""
    verts: list[tuple] = []
    faces: list[tuple] = []
    for _ in range(draw(st.integers(1, 4))):
        size = draw(st.sampled_from([3, 3, 4, 4, 4, 5, 6]))
        face = []
        for _corner in range(size):
            kind = draw(st.sampled_from(["new"] * 6 + ["shared", "copy", "near", "far", "bad"]))
            if kind == "shared" and verts:
                index = draw(st.integers(0, len(verts) - 1))
                if index in face:
                    kind = "new"
                else:
                    face.append(index)
                    continue
            if kind == "copy" and verts:
                # A vertex of its own at another's exact position (an
                # unmerged seam, a pole): edges of length 0 (§3.2).
                verts.append(verts[draw(st.integers(0, len(verts) - 1))])
            elif kind == "near" and face:
                base = verts[face[-1]]
                offset = draw(st.tuples(*[st.floats(-1e-3, 1e-3)] * 3))
                verts.append(tuple(b + o for b, o in zip(base, offset)))
            elif kind == "far":
                verts.append(tuple(draw(st.floats(-40.0, 40.0)) for _ in range(3)))
            elif kind == "bad":
                # Non-finite, or past what float32 can square (3e38 is what
                # Blender stores for inf; 2e19): dropped as NaN is, image
                # model §2.1, whatever the object's scale.
                value = draw(st.sampled_from([math.nan, math.inf, -math.inf, 3.0e38, -2.0e19]))
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


def empty_fuzz_scene(line, transform):
    """An empty scene with ``line``'s settings and ``transform``'s pixel
    aspect."""
    # diagonal_mode's update resets the duty: set the mode first.
    line = dict(line)
    duty = line.pop("pattern_duty", None)
    scene = scenes.empty_scene(W, H, **line)
    if duty is not None:
        scene.solidwire.pattern_duty = duty
    scene.render.pixel_aspect_x = transform.get("pixel_aspect", 1.0)
    return scene


def add_fuzz_mesh(scene, mesh):
    """The object "Fuzz" of ``mesh`` (vertices, faces) in ``scene``."""
    verts, faces = mesh
    data = bpy.data.meshes.new("Fuzz")
    data.from_pydata(verts, [], faces)
    data.update()
    obj = bpy.data.objects.new("Fuzz", data)
    scene.collection.objects.link(obj)
    return obj


def build(mesh, camera, line, transform):
    scene = empty_fuzz_scene(line, transform)
    obj = add_fuzz_mesh(scene, mesh)
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
    with recipe_on_failure(repro(mesh, camera, line, transform)):
        check(scene, path)


@contextmanager
def recipe_on_failure(recipe: str):
    """Print how to rebuild the example when the block fails (hypothesis
    shrinks no render: the recipe is what a person has to go on)."""
    try:
        yield
    except Exception:
        print("\n--- fuzz scene ---\n" + recipe)
        raise


def scene_recipe(camera, line, transform, **content) -> str:
    """The recipe of a scene of ``content`` (its objects, its source) seen
    by ``camera`` with the settings ``line`` under ``transform``."""
    parts = [f"{name}={value!r}" for name, value in content.items()]
    return "\n".join([*parts, f"camera={camera!r}", f"settings={line!r}", f"transform={transform!r}"])


def without_marks(line: dict) -> dict:
    """The settings of a rich_settings() draw, less which edges it marks
    (the scenes that take it mark their own)."""
    return {key: value for key, value in line.items() if key != "marked"}


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


# Found by a hunt on bpy 5.3.0: a folded hexagon under an orthographic
# camera and the depth fade; a pixel centre 6.4e-4 px inside the triangle
# in front, whose neighbour of the same face lies behind it there (depth
# 1.22 against 2.34). The rasteriser showed the one behind, and the fade
# read its depth (image model §7.2: a folded face's contour is undecided).
FOLD_CONTOUR = dict(
    mesh=(
        [
            (1.52681368680942e-54, 1.7734495525463378, 0.010972640954281854),
            (-1.4012984627980034e-45, 1.7734495525463378, 0.010972640954281854),
            (1.118540077522332, 1.1, 0.2),
            (-0.03638775534670957, 0.7963503272893173, 0.33737717331158334),
            (19.210129946140945, -10.159397681167729, 2.5999457509724736e-161),
            (-2.9354778513772675e-230, -1.5330173947233714, 1.5735905126137348),
            (-1.192092896e-07, 2.0, 5.798281345325984e-254),
            (-1.4772421521139483e-42, 0.016820675837817323, -1.0532015464771476e-271),
            (-0.05303335954771482, 2.6344668533821883e-170, 0.20665918479568246),
            (28.707942827049337, -1.598570942160201e-05, -16.298339892153596),
            (-0.07758687294281286, 1.1, 1e-06),
            (1.6339493580423676, 0.0, 1.5965364917565372),
            (1.0573721699423926, -0.24617822644396314, 1.6213769750610542e-286),
            (2.225073858507e-311, 1.3065280682694125, -2.255770810493117e-266),
            (1.8363943712544408, -4.3964552380936566e-172, -1.6504258554554907),
        ],
        [(0, 1, 2, 3, 4), (5, 6, 7, 8, 9, 10), (11, 12, 13, 14)],
    ),
    camera={
        "location": (0.8765036950419971, -0.9818322099389332, 0.33737717331158334),
        "target": (-0.03638775534670957, 0.7963503272893173, 0.33737717331158334),
        "lens": 61.402075529585204,
        "ortho_scale": 5.434367389734665,
        "shift": (-8.590151161070602e-243, -0.2647341940052961),
        "clip": (0.1, 20.0),
        "sensor_fit": "HORIZONTAL",
    },
    line={
        "thickness": 3.0,
        "softness": 100.0,
        "diagonal_mode": "SOLID",
        "use_backface_culling": False,
        "use_fade": True,
        "fade_start": 0.23653788687198146,
        "fade_end": 9.707093852047185,
        "edge_angle": 1.0,
        "use_boundary_edges": True,
        "boundary_thickness": 3.9314063383492153,
        "boundary_pattern": "SOLID",
        "use_density_fade": True,
        "density_fade_length": 4.0,
    },
    transform={
        "rotation": (-3.18778952377472e-222, 2.9858437246395573, -2.4438812189233317),
        "scale": (0.763904116754128, -1.7265540859485773, -1.9127558804062568),
        "location": (-0.2218211363157478, -0.2, 0.033729368163820106),
        "pixel_aspect": 1.0,
    },
)


@FUZZ
@example(**FOLD_CONTOUR)
@given(mesh=polygons(), camera=cameras(), line=edge_settings(), transform=transforms())
def test_random_edge_selections_match_reference(mesh, camera, line, transform, tmp_path_factory):
    check_example(mesh, camera, line, transform, tmp_path_factory.getbasetemp() / "fuzz_edges.exr")


@st.composite
def rich_settings(draw):
    """edge_settings plus what the other random-mesh tests leave out: the
    thickness modes (§4.2), hidden lines (§5.4), full silhouettes (§5.5)
    and the classes marked on edges (sharp, seam, crease: §3.6), with their
    own widths and patterns. ``marked``: which edges carry a mark
    (build_marked)."""
    values = draw(edge_settings())
    mode = draw(st.sampled_from(["PIXELS", "WORLD", "DEPTH"]))
    values["thickness_mode"] = mode
    if mode == "WORLD":
        values["world_thickness"] = draw(st.sampled_from([0.0, 0.01, 0.05, draw(st.floats(0.0, 0.5))]))
    elif mode == "DEPTH":
        values["thickness_far"] = draw(st.sampled_from([0.0, 0.5, 4.0, draw(st.floats(0.0, 10.0))]))
        values["thickness_depth_start"] = draw(st.floats(0.0, 10.0))
        values["thickness_depth_end"] = draw(st.floats(0.0, 15.0))
    if draw(st.booleans()):
        values["use_hidden_lines"] = True
        values["hidden_alpha"] = draw(st.sampled_from([0.35, 1.0, draw(st.floats(0.0, 1.0))]))
        values["hidden_period"] = draw(st.floats(1.0, 20.0))
        values["hidden_duty"] = draw(st.sampled_from([0.5, 1.0, draw(st.floats(0.0, 1.0))]))
    values["use_silhouettes"] = draw(st.booleans())
    for name in ("sharp", "seam", "crease"):
        if draw(st.booleans()):
            values[f"use_{name}_edges"] = True
            values[f"{name}_thickness"] = draw(st.sampled_from([0.0, 2.5, draw(st.floats(0.0, 6.0))]))
            values[f"{name}_pattern"] = draw(st.sampled_from(["SOLID", "DOTTED", "DASHED"]))
    values["marked"] = draw(st.integers(0, 2**16 - 1))
    return values


def mark_edges(mesh, marked: int):
    """Edge k marked where bit k % 16 of ``marked`` is set: sharp, seam or
    crease by k % 3 (as build_stack marks a cage)."""
    flags = [bool((marked >> (k % 16)) & 1) for k in range(len(mesh.edges))]
    for k, edge in enumerate(mesh.edges):
        edge.use_edge_sharp = flags[k] and k % 3 == 0
        edge.use_seam = flags[k] and k % 3 == 1
    crease = mesh.attributes.new("crease_edge", "FLOAT", "EDGE")
    crease.data.foreach_set("value", [float(flag and k % 3 == 2) for k, flag in enumerate(flags)])


# Found by the hunts: a pentagon whose two triangles lie behind a sample
# 3.9e-6 of their depth apart (one hidden layer to the engine, image model
# §7.2).
FOLDED_NEARLY_LEVEL = dict(
    mesh=(
        [
            (-0.8847751235014252, 0.29729152417057536, 1.9554291893340139),
            (-0.5292941370054078, -0.37256873716874184, 2.852835577893168e-220),
            (-0.6761050144190948, -1.0734186221169233, 0.21893385275162602),
            (-1.033520189122109, 1.6227757526700453, 0.2689320075088415),
            (1.035271503875948, -0.616713524056453, 1e-05),
            (1.1754943508222875e-38, -6.213247460973314e-57, -1.0460816781192383e-151),
            (1.1754943508222875e-38, -6.213247460973314e-57, -0.0003381182214388269),
            (1.9, 1.782258918511404e-81, -34.531854811805296),
            (-1.1754943508222875e-38, -0.3724475045790103, -1.8371413008692636),
            (0.25, 0.3949316046859175, 1.034459676546331),
            (-1.70421075759009, 0.7070754297438149, 0.2),
            (-6.496459604335891e-111, 4.172271842561932e-159, 1.1076242580103274e-262),
            (1.874686815646129, 1.760740747580269, -5.1759538291011805e-179),
            (0.698649232541078, -4.4505206292212256e-281, 0.9808792872157643),
            (0.2985319174591283, -1.460843273942607, -1.4692739696529955),
        ],
        [(0, 1, 2, 3), (4, 5, 6), (7, 8, 9, 10, 11), (12, 13, 14)],
    ),
    camera={
        "location": (9.753767175190521, 0.8582343051953614, 0.9766056955821507),
        "target": (-0.6880170664013643, 0.8582343051953614, 0.9766056955821507),
        "lens": 51.11206158881177,
        "ortho_scale": None,
        "shift": (0.0009830351809859694, 0.0),
        "clip": (0.1, 20.0),
        "sensor_fit": "HORIZONTAL",
    },
    line={
        "thickness": 0.5,
        "softness": 1.3509349978009022,
        "diagonal_mode": "SOLID",
        "use_backface_culling": False,
        "use_fade": False,
        "fade_start": 5.176362238722777,
        "fade_end": 3.577771956019321,
        "edge_angle": 0.0,
        "use_boundary_edges": True,
        "boundary_thickness": 0.0,
        "boundary_pattern": "DASHED",
        "thickness_mode": "WORLD",
        "world_thickness": 0.0,
        "use_hidden_lines": True,
        "hidden_alpha": 0.35,
        "hidden_period": 2.00001,
        "hidden_duty": 0.5,
        "use_silhouettes": False,
        "use_seam_edges": True,
        "seam_thickness": 0.0,
        "seam_pattern": "DOTTED",
        "use_crease_edges": True,
        "crease_thickness": 2.5,
        "crease_pattern": "SOLID",
        "marked": 4,
    },
    transform={
        "rotation": (-3.141592653589793, -5.9959079925219186e-55, -0.5801911528381156),
        "scale": (1.8735378152322573, 1.3967553425098944, 0.8694785446151123),
        "location": (0.5, 0.11636895967225114, 0.05),
        "pixel_aspect": 2.0,
    },
)


# An overlay hunt's scene (the fold of a bent hexagon 9 units away, near
# clip 0.01): a silhouette through the near plane whose outer half reaches
# a sample where its nearest point lies 1e-4 of the distance behind the
# visible surface. The render hides it there, as the model says; the
# overlay's depth bias at that near clip cannot (image model §5.6), so the
# overlay test leaves such samples out.
OUTER_HALF_WITHIN_BIAS = dict(
    mesh=(
        [
            (-32.41914215895079, -5e-324, 8.0),
            (0.3, 7.362783868220393e-128, -0.9579283640683609),
            (1.9752375375444187, -0.10865568834745121, -5.960464477539063e-08),
            (3.0222150167900357e-24, -0.29061743067289525, 1.0481263182668448),
            (3.0222150167900357e-24, -0.2898337901126473, 1.0483775688031738),
            (-1.039567082182815, 4.487198836228724e-199, -1.867664790555911),
            (0.14312416922025717, 1.1953234449336638e-283, 1.0),
            (-1.8291575456180666, -1.175494351e-38, 0.9644440883728644),
            (1e-300, -0.5823352983612222, 2.460188473049242e-68),
        ],
        [(0, 1, 2), (3, 4, 5, 6, 7, 8)],
    ),
    camera={
        "location": (2.4465409505720923, 0.23196851324872345, -9.241966466829224),
        "target": (-4.0110551782989364e-277, 0.25, -5.876258827282444e-26),
        "lens": 93.23938792819185,
        "ortho_scale": None,
        "shift": (0.2974720174114847, -2.0918144887919123e-100),
        "clip": (0.01, 100.0),
        "sensor_fit": "HORIZONTAL",
    },
    line={
        "thickness": 3.0,
        "softness": 2.5,
        "diagonal_mode": "DOTTED",
        "use_backface_culling": False,
        "use_fade": False,
        "fade_start": 0.9233702414760782,
        "fade_end": 4.530639190217114,
        "pattern_period": 2.878262337165837,
        "pattern_duty": 0.0,
        "edge_angle": 0.2,
        "use_boundary_edges": True,
        "boundary_thickness": 0.0,
        "boundary_pattern": "SOLID",
        "use_density_fade": True,
        "density_fade_length": 4.0,
        "thickness_mode": "WORLD",
        "world_thickness": 0.46304742449737935,
        "use_hidden_lines": True,
        "hidden_alpha": 0.35,
        "hidden_period": 18.750363712314556,
        "hidden_duty": 0.5,
        "use_silhouettes": True,
        "use_crease_edges": True,
        "crease_thickness": 0.016226827591060203,
        "crease_pattern": "DASHED",
        "marked": 49209,
    },
    transform={
        "rotation": (1e-30, 0.7123850847828126, 1.9307584951877672),
        "scale": (-1.8273613323274565, 1.5, 0.6184552957048339),
        "location": (0.001, 0.4989069207017385, -0.39223939581563805),
        "pixel_aspect": 1.0,
    },
)


# A hunt's scene (every line option, the render): a triangle seen nearly
# edge-on, its sharp tip 0.0012 px beside two pixel centres, where it is
# 0.002 px wide; the rasteriser covered them, every probe 0.01 px off
# passed beside it (image model §7.2: a snapping step).
SHARP_TIP = dict(
    mesh=(
        [
            (1.672954935330857, -2.1901812721062697e-171, 0.055),
            (0.0, 0.0, 0.21687179616334928),
            (-5.449154054348433e-31, 0.0, 0.0),
            (-1.965918879784856, 0.0, 0.0),
            (-18.17828205329796, -29.903481982522173, 3.6275171636453115e-111),
            (-0.8967787028625487, 0.2110849978372955, -math.inf),
        ],
        [(0, 1, 2), (3, 4, 5)],
    ),
    camera={
        "location": (0.7478810141301162, -0.21151952065267526, -0.4725130359273385),
        "target": (1.8926943201609813e-290, -0.15518135682291478, -0.4725130359273385),
        "lens": 16.0,
        "ortho_scale": None,
        "shift": (0.288187946048638, -0.06791480285832915),
        "clip": (0.01, 100.0),
        "sensor_fit": "HORIZONTAL",
    },
    line={
        "thickness": 40.0,
        "softness": 100.0,
        "diagonal_mode": "HIDDEN",
        "use_backface_culling": False,
        "use_fade": True,
        "fade_start": 0.5880388208629085,
        "fade_end": 12.640707203117724,
        "edge_angle": 3.0,
        "thickness_mode": "DEPTH",
        "thickness_far": 0.0,
        "thickness_depth_start": 3.7931361538598916,
        "thickness_depth_end": 11.078239915960406,
        "use_silhouettes": False,
        "marked": 2,
    },
    transform={"rotation": (0.0, 0.0, 0.0), "scale": (0.3, 0.3, 0.3), "location": (0.0, 0.0, 0.0), "pixel_aspect": 1.0},
)


# An overlay hunt's scene, in the render too (docs/dev/robustness.md:
# "a folded n-gon's hidden layer within the error bound of the surface"):
# the far one of a folded pentagon's two triangles behind a sample takes
# its sibling's depth less that depth's float32 error bound; through the
# near plane that bound, from the corners' own window coordinates, came to
# 1e-3 of the depth, more than the sibling's gap to the surface, and one
# hidden layer of two was dropped (1 pixel, 0.19). The overlay still drops
# it (open): it tests in window depth, where with a near clip of 0.01 that
# gap is 1.2e-5, about 100 float32 steps, less than the window depth of a
# triangle through the near plane may move. A strict expected failure
# there: it passes, and so fails, once that is fixed.
HIDDEN_LAYER_WITHIN_BOUND = dict(
    mesh=(
        [
            (-3.323503866642227e-12, -1.829236749135232, -1.1570067258617411),
            (-3.323503866642227e-12, -1.8292714868147226, -1.157006785466386),
            (0.2, 0.76, -0.17953109668607103),
            (1.4128950016444229e-155, 4.52394709911983e-123, 0.349),
            (0.0, -1.9623640642063345, -1.6355172190291603),
            (-0.0007652639007150323, 0.0009747487472645676, 0.0006718358183818607),
            (-3.323503866642227e-12, -1.829236749135232, -1.1570067258617411),
            (1.4128950016444229e-155, 4.52394709911983e-123, 0.349),
            (0.0, 0.0, 0.0),
            (9.84256083726575e-25, 1.446826723677094, 0.0),
            (1.7187673523392424e-135, 0.0, 0.0006718358183818607),
            (0.0, 0.0, 5.942163630774628e-280),
            (0.0007654405855413988, 0.0, 0.0),
        ],
        [(0, 1, 2, 3, 4), (5, 6, 7, 8, 9), (10, 11, 12)],
    ),
    camera={
        "location": (0.6712467790792587, 0.0052254478102189035, 0.0012042739495391154),
        "target": (0.3712947088756391, 0.0, 0.0),
        "lens": 12.0,
        "ortho_scale": None,
        "shift": (0.0, 0.0),
        "clip": (0.01, 20.0),
        "sensor_fit": "AUTO",
    },
    line={
        "thickness": 3.0,
        "softness": 0.01,
        "diagonal_mode": "HIDDEN",
        "use_backface_culling": False,
        "use_fade": False,
        "fade_start": 0.0,
        "fade_end": 8.555903384780046e-192,
        "edge_angle": 0.0,
        "use_density_fade": True,
        "density_fade_length": 1.141220452248736,
        "thickness_mode": "DEPTH",
        "thickness_far": 0.5,
        "thickness_depth_start": 0.1260668107174633,
        "thickness_depth_end": 0.0,
        "use_hidden_lines": True,
        "hidden_alpha": 0.2528155584776231,
        "hidden_period": 16.864863413642546,
        "hidden_duty": 0.5,
        "use_silhouettes": False,
        "use_sharp_edges": True,
        "sharp_thickness": 3.1920260833660254,
        "sharp_pattern": "SOLID",
        "use_seam_edges": True,
        "seam_thickness": 0.0,
        "seam_pattern": "SOLID",
        "marked": 642,
    },
    transform={
        "rotation": (0.6722175998559012, 2.0299840055874787, 1.1767688827265112e-18),
        "scale": (0.9150259212827181, -1.3214562013386955, -1.9862480243996279),
        "location": (-0.3027913269815276, 0.47016454292020976, 0.39695089966996555),
        "pixel_aspect": 1.0,
    },
)


@FUZZ
@given(mesh=polygons(), camera=cameras(), line=rich_settings(), transform=transforms())
@example(**FOLDED_NEARLY_LEVEL)
@example(**SHARP_TIP)
@example(**HIDDEN_LAYER_WITHIN_BOUND)
def test_random_meshes_with_every_line_option_match_reference(mesh, camera, line, transform, tmp_path_factory):
    """Random meshes under every line option at once. A long hunt also
    reports the difference image model §5.4 (an n-gon folded three deep)
    names as SolidWire's own; anything else it finds is new."""
    line = dict(line)
    marked = line.pop("marked")
    log.forget()
    scene = build(mesh, camera, line, transform)
    mark_edges(scene.objects["Fuzz"].data, marked)
    with recipe_on_failure(repro(mesh, camera, line, transform) + f"\nmarked={marked!r}"):
        check(scene, tmp_path_factory.getbasetemp() / "fuzz_rich.exr")


@st.composite
def folded_faces(draw):
    """The corners of one face of 4 to 6 corners around the view of a
    camera at the origin looking along +Y (folded_face_scene): folded, so
    that its triangles overlap on screen, and often through the near plane
    (0.01), with corners behind the camera."""
    size = draw(st.integers(4, 6))
    return [(draw(st.floats(-1.0, 1.0)), draw(st.floats(-0.6, 2.0)), draw(st.floats(-1.0, 1.0))) for _ in range(size)]


def folded_face_scene(corners, hidden: bool):
    scene = scenes.empty_scene(W, H, thickness=3.0, use_hidden_lines=hidden, hidden_alpha=1.0, hidden_duty=1.0)
    scenes.from_pydata(scene, "Folded", corners, [tuple(range(len(corners)))])
    scenes.add_camera(scene, location=(0.0, 0.0, 0.0), target=(0.0, 1.0, 0.0), lens=12.0, clip=(0.01, 100.0))
    return scene


def assert_no_layer_of_itself(corners, draw, decided=lambda ref: ~ref.on_silhouette):
    """One folded face (folded_face_scene) drawn by ``draw`` (scene -> alpha)
    with hidden lines and without must agree where ``decided`` (of the
    reference with its depth layers) holds: beside a silhouette (a fold's
    own edge included) the rasteriser's snapping decides which triangles
    cover a pixel (image model §7.2)."""
    plain, hidden = (draw(folded_face_scene(corners, with_hidden)) for with_hidden in (False, True))
    assert np.isfinite(hidden).all(), "NaN/Inf pixels"
    mask = decided(reference.render_reference(folded_face_scene(corners, True), depth_layers=True))
    difference = np.abs(hidden - plain)[mask]
    assert difference.max(initial=0.0) <= 2 / 255, f"a layer of the face itself: corners={corners!r}"


@FUZZ
@given(corners=folded_faces())
# Two faces whose triangles behind the surface showed as layers of their own
# with partner_depth_error at 0 (4 of 400 random faces did): one through
# the near plane, one in front of it.
@example(
    corners=[
        (-0.806, -0.0678, 0.503),
        (0.4263, 1.8159, 0.7276),
        (-0.0621, 1.1233, -0.7796),
        (0.4007, 1.372, -0.5772),
        (-0.7773, 0.1335, 0.783),
        (-0.7802, 1.4171, -0.6384),
    ]
)
@example(
    corners=[
        (0.7722, 1.4549, -0.4323),
        (-0.1269, 0.9862, -0.9776),
        (0.0615, 0.7687, 0.2734),
        (-0.7803, 0.6001, 0.3203),
        (-0.8156, 0.0204, 0.6205),
    ]
)
def test_a_random_folded_face_is_no_hidden_layer_of_itself(corners, tmp_path_factory):
    """A face is never a hidden layer of itself (image model §5.4): one face
    alone, however folded, draws the same with hidden lines as without,
    away from its silhouettes. Its triangles behind its own surface take
    their nearer sibling's depth less float32's error bound of it
    (shaders/quad_partner.glsl); a bound too small shows them, one too
    large drops a layer behind another face (HIDDEN_LAYER_WITHIN_BOUND)."""
    path = tmp_path_factory.getbasetemp() / "fuzz_folded.exr"
    assert_no_layer_of_itself(corners, lambda scene: robustness.render_exr(scene, path)[..., 3])


@FUZZ
@given(corners=folded_faces())
# Faces whose triangles behind the surface showed as layers of their own in
# the overlay with partner_depth_error at 0 (2 of 300 random faces did),
# both through the near plane.
@example(
    corners=[
        (-0.4245, 1.7607, -0.1459),
        (0.7005, 1.889, 0.3637),
        (0.2629, -0.5283, -0.2569),
        (-0.7433, 1.3538, 0.6956),
        (0.8001, 0.6228, -0.0764),
        (0.1474, -0.3324, 0.1116),
    ]
)
@example(
    corners=[
        (-0.0947, -0.4004, -0.8733),
        (0.4566, -0.4233, 0.2166),
        (0.9254, -0.3527, -0.2709),
        (0.0123, 1.1078, 0.186),
        (0.0152, 1.363, -0.5683),
        (-0.7716, -0.2564, -0.538),
    ]
)
def test_a_random_folded_face_is_no_hidden_layer_of_itself_in_the_overlay(corners):
    """The same in the viewport overlay's first redraw, whose layers are
    tested in window depth against Blender's Solid shading depth of the
    face, away from where that depth decides (as check_overlay)."""
    viewport = robustness.Viewport(W, H)
    assert_no_layer_of_itself(
        corners,
        lambda scene: viewport.draw(scene)[1].copy(),
        lambda ref: ~ref.on_silhouette & ~viewport.blender_decides(ref),
    )


@FUZZ
@given(mesh=polygons(), camera=cameras(), line=rich_settings(), transform=transforms())
@example(**FOLDED_NEARLY_LEVEL)
@example(**OUTER_HALF_WITHIN_BIAS)
@example(**HIDDEN_LAYER_WITHIN_BOUND).xfail(raises=AssertionError, reason="open: window depth near a 0.01 near clip")
def test_random_meshes_with_every_line_option_in_the_overlay(mesh, camera, line, transform):
    """The same scenes in the viewport overlay's first redraw over
    Blender's Solid shading depth of them (image model §5.6), compared with
    the reference wherever that depth agrees with the model. Where Blender
    draws a surface nearer than the model's visible one (a face with a
    non-finite corner, which the model drops; a sliver seen edge-on, which
    it never hits) nothing of ours can show, and the picture there is
    Blender's. Where a surface of ours lies behind the visible one by less
    than the overlay's depth bias (at a near clip of 0.01 about 0.1 % of
    the distance 5 units away), Blender's depth test cannot tell the two
    apart (§5.6): both show, or a hidden layer there does not, and the
    same holds for a silhouette's outer half whose nearest point lies
    that little behind the surface (the model hides it); and two
    triangles lying on one another at the surface's depth (a quad or an
    n-gon whose outline crosses itself) both blend their wire where the
    overlay draws a mesh directly (§5.6). Outer halves
    of silhouettes blend "over" one another in the overlay (§5.5): where
    they reach, the overlay may be darker than the reference, never
    lighter."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    line = dict(line)
    marked = line.pop("marked")
    log.forget()
    ensure_gpu()
    scene = build(mesh, camera, line, transform)
    mark_edges(scene.objects["Fuzz"].data, marked)
    with recipe_on_failure(repro(mesh, camera, line, transform) + f"\nmarked={marked!r}"):
        check_overlay(scene)


def check_overlay(scene, size=(W, H)):
    """The overlay's first redraw of ``scene`` at ``size`` over Blender's
    Solid shading depth against the reference, as
    test_random_meshes_with_every_line_option_in_the_overlay says."""
    viewport = robustness.Viewport(*size)
    _stats, alpha = viewport.draw(scene)
    assert np.isfinite(alpha).all(), "NaN/Inf pixels"
    ref = reference.render_reference(scene, depth_layers=True)
    blender_decides = viewport.blender_decides(ref)
    outer = np.zeros_like(blender_decides)
    if scene.solidwire.use_silhouettes:
        without = reference.SettingsWith(scene.solidwire, use_silhouettes=False)
        outer = ref.intensity != reference.render_reference(scene, settings=without).intensity
        lighter = (alpha < ref.intensity - 0.1) & outer & ~blender_decides & ~ref.on_silhouette
        assert not lighter.any(), f"{int(lighter.sum())} pixels lack outer halves"
    ref.on_silhouette = ref.on_silhouette | blender_decides | outer
    accuracy.assert_accurate(reference.error_report(alpha, ref))


# Several objects, each with its own settings (SPEC 3.3, image model §5.9):
# an override's Thickness (0 included), which its classes' widths follow
# under every thickness mode (§3.6), or an object left out of the render;
# some instanced (an instance takes the settings of the object it
# instances).
@st.composite
def styled_objects(draw):
    """1-3 random meshes, each with its edge marks, an offset, None (the
    scene's settings), a Thickness override or "hidden" (Show in Render
    off), and 0-2 collection instances of it."""
    objects = []
    for _ in range(draw(st.integers(1, 3))):
        objects.append(
            {
                "mesh": draw(polygons()),
                "marked": draw(st.integers(0, 2**16 - 1)),
                "offset": draw(st.tuples(*[st.floats(-1.0, 1.0)] * 3)),
                "style": draw(st.sampled_from([None, None, "hidden", 0.0, 0.5, 6.0, draw(st.floats(0.0, 10.0))])),
                # Collection instances of it (offset, rotation, scale, some
                # mirrored), the object itself drawn too or not.
                "instances": draw(st.lists(instance_transforms(), max_size=2)),
                "keep_original": draw(st.booleans()),
            }
        )
    return objects


@st.composite
def instance_transforms(draw):
    sign = draw(st.sampled_from([(1, 1, 1), (1, 1, 1), (-1, 1, 1), (1, -1, -1)]))
    return (
        draw(st.tuples(*[st.floats(-1.5, 1.5)] * 3)),
        draw(st.tuples(*[st.floats(-math.pi, math.pi)] * 3)),
        tuple(k * draw(st.floats(0.5, 1.5)) for k in sign),
    )


def build_styled(objects, camera, line, transform):
    """``objects`` (styled_objects) under ``transform``, each moved by its
    offset, in one scene of ``line``'s settings."""
    scene = empty_fuzz_scene(line, transform)
    for index, item in enumerate(objects):
        obj = add_fuzz_mesh(scene, item["mesh"])
        obj.name = f"Fuzz{index}"
        mark_edges(obj.data, item["marked"])
        obj.rotation_euler, obj.scale = transform["rotation"], transform["scale"]
        obj.location = tuple(a + b for a, b in zip(transform["location"], item["offset"]))
        if item["style"] == "hidden":
            obj.solidwire.show_in_render = False
            obj.solidwire.show_in_viewport = False
        elif item["style"] is not None:
            # Colours apart: the alpha compared is the wire's intensity.
            obj.solidwire.use_override = True
            obj.solidwire.thickness = item["style"]
        _instance(scene, obj, item["instances"], item["keep_original"])
    scenes.add_camera(scene, **camera)
    return scene


def _instance(scene, obj, transforms, keep_original: bool) -> None:
    """Collection instances of ``obj`` under ``transforms`` (none: nothing
    changes); ``obj`` itself leaves the scene unless ``keep_original``."""
    if not transforms:
        return
    collection = bpy.data.collections.new(f"{obj.name}Set")
    collection.objects.link(obj)
    if not keep_original:
        scene.collection.objects.unlink(obj)
    for k, (location, rotation, scale) in enumerate(transforms):
        empty = bpy.data.objects.new(f"{obj.name}Copy{k}", None)
        empty.instance_type, empty.instance_collection = "COLLECTION", collection
        empty.location, empty.rotation_euler, empty.scale = location, rotation, scale
        scene.collection.objects.link(empty)


STYLED_SCENES = dict(objects=styled_objects(), camera=cameras(), line=rich_settings(), transform=transforms())


@FUZZ
@given(**STYLED_SCENES)
def test_random_objects_with_their_own_settings_match_reference(objects, camera, line, transform, tmp_path_factory):
    """Up to three random meshes with every line option, each drawn with the
    scene's settings, its own Thickness or not at all."""
    line = without_marks(line)
    log.forget()
    scene = build_styled(objects, camera, line, transform)
    with recipe_on_failure(scene_recipe(camera, line, transform, objects=objects)):
        check(scene, tmp_path_factory.getbasetemp() / "fuzz_styled.exr")


@FUZZ
@given(**STYLED_SCENES)
def test_random_objects_with_their_own_settings_in_the_overlay(objects, camera, line, transform):
    """The same scenes in the overlay's first redraw, compared as the
    meshes' overlay test does. An object SolidWire does not show still
    fills Blender's Solid depth, as in Blender: where it lies in front,
    Blender's depth decides, and those pixels are left out."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    line = without_marks(line)
    log.forget()
    ensure_gpu()
    scene = build_styled(objects, camera, line, transform)
    with recipe_on_failure(scene_recipe(camera, line, transform, objects=objects)):
        check_overlay(scene)


# Fill and wire colours (image model §5.1, §5.2, §5.8): every colour
# source over random meshes with materials, object colours and colour
# attributes of both domains and types, flat, Studio-lit or matcap-lit.
channel = st.floats(0.0, 1.0)
colour = st.tuples(channel, channel, channel)


@st.composite
def colour_looks(draw):
    """line_settings with the fill on and every colour source and shading."""
    values = draw(line_settings())
    values.update(
        use_fill=True,
        fill_shading=draw(st.sampled_from(["FLAT", "STUDIO", "MATCAP"])),
        # (Bundled with every Blender from 4.2 on; 5.0 renamed others.)
        matcap=draw(st.sampled_from(["clay_studio", "metal_carpaint", "check_rim_dark"])),
        fill_color_source=draw(st.sampled_from(["SINGLE", "OBJECT", "MATERIAL", "RANDOM", "ATTRIBUTE"])),
        wire_color_source=draw(st.sampled_from(["SINGLE", "OBJECT", "RANDOM"])),
        fill_color=draw(colour),
        wire_color=(*draw(colour), draw(st.sampled_from([1.0, 1.0, 0.5, 0.0, draw(channel)]))),
    )
    return values


@st.composite
def paints(draw):
    """What colours a mesh: its object colour, 0-2 materials (an empty slot
    among them) over its faces, and a colour attribute (or none)."""
    return {
        "object_color": draw(colour),
        "materials": draw(st.lists(st.none() | colour, max_size=2)),
        "material_of_face": draw(st.lists(st.integers(0, 3), min_size=6, max_size=6)),
        "attribute": draw(
            st.none() | st.tuples(st.sampled_from(["POINT", "CORNER"]), st.sampled_from(["BYTE_COLOR", "FLOAT_COLOR"]))
        ),
        "attribute_seed": draw(st.integers(0, 2**16)),
        "smooth": draw(st.booleans()),
    }


def paint(obj, paint_recipe):
    """Colour ``obj`` as ``paint_recipe`` (paints) says."""
    mesh = obj.data
    obj.color = (*paint_recipe["object_color"], 1.0)
    for k, rgb in enumerate(paint_recipe["materials"]):
        material = None
        if rgb is not None:
            material = bpy.data.materials.new(f"Paint{k}")
            material.diffuse_color = (*rgb, 1.0)
        mesh.materials.append(material)
    for poly in mesh.polygons:
        poly.material_index = paint_recipe["material_of_face"][poly.index % 6]
        poly.use_smooth = paint_recipe["smooth"]
    if paint_recipe["attribute"] is not None:
        domain, data_type = paint_recipe["attribute"]
        attribute = mesh.color_attributes.new("Paint", data_type, domain)
        rng = np.random.default_rng(paint_recipe["attribute_seed"])
        values = rng.uniform(0.0, 1.0, (len(attribute.data), 4)).astype(np.float32)
        values[:, 3] = 1.0
        attribute.data.foreach_set("color", values.ravel())
        mesh.color_attributes.active_color = attribute


@FUZZ
@given(mesh=polygons(), paint_recipe=paints(), camera=cameras(), line=colour_looks(), transform=transforms())
def test_random_colours_match_reference(mesh, paint_recipe, camera, line, transform, tmp_path_factory):
    """Random meshes under every fill and wire colour source and fill
    shading: the file's colours against the reference's (A c_w + (1 - A)
    times the shaded fill), as tests/test_fill_shading.py measures them."""
    log.forget()
    scene = build(mesh, camera, line, transform)
    paint(scene.objects["Fuzz"], paint_recipe)
    with recipe_on_failure(repro(mesh, camera, line, transform) + f"\npaint={paint_recipe!r}"):
        rgba = scenes.render_to_file(scene, tmp_path_factory.getbasetemp() / "fuzz_colours.png")
        ref = reference.render_reference(scene)
        expected = reference.expected_fill_rgb(ref, float(scene.solidwire.wire_color[3]))
        accuracy.assert_accurate(reference.color_error_report(rgba, expected, ref))


# Modifier stacks under cage edges (image model §3.5): a primitive, what
# comes before its Subdivision Surface (nothing, a deform, or modifiers
# that make new edges, which are cage edges too), the subdivision, and what
# comes after it (deforms and the Mirror, Array and Weld that keep the cage;
# a Triangulate that drops it).
SHAPES = {
    "cube": lambda scene: scenes.cube(scene, size=1.6),
    "tube": lambda scene: scenes.tube(scene, segments=7, depth=1.4),
    "cone": lambda scene: scenes.tube(scene, segments=5, depth=1.4, top_radius=0.3),
    "grid": lambda scene: scenes.grid(scene, x_segments=3, y_segments=2, size=1.0),
    "sphere": lambda scene: scenes.uv_sphere(scene, segments=8, rings=4),
    "monkey": lambda scene: scenes.monkey(scene),
}
SIZE = (80, 60)
BEFORE_SUBDIVISION = ["BEVEL", "SOLIDIFY", "TRIANGULATE", "MIRROR", "SIMPLE_DEFORM"]
AFTER_SUBDIVISION = ["MIRROR", "ARRAY", "WELD", "SIMPLE_DEFORM", "CAST", "DISPLACE", "TRIANGULATE"]


@st.composite
def cage_stacks(draw):
    before = draw(st.sampled_from([None, *BEFORE_SUBDIVISION]))
    after = draw(st.lists(st.sampled_from(AFTER_SUBDIVISION), max_size=2))
    before = [] if before is None else [before]
    # One Mirror at most: a second one on the same axis would lay the
    # copies on one another.
    after = [kind for k, kind in enumerate(after) if kind != "MIRROR" or "MIRROR" not in before + after[:k]]
    return {
        "shape": draw(st.sampled_from(sorted(SHAPES))),
        "before": before,
        "level": draw(st.integers(1, 3)),
        "optimal_display": draw(st.sampled_from([True, True, True, False])),
        "after": after,
        # Per modifier: its variant (_add_modifier) and a Mirror's axes.
        "variant": [draw(st.booleans()) for _ in before + after],
        "axes": [draw(st.sampled_from([(0,), (1,), (0, 1)])) for _ in before + after],
        # Edge k is marked where bit k % 16 is set: sharp, seam or crease by k % 3.
        "marked": draw(st.integers(0, 2**16 - 1)),
    }


@st.composite
def cage_looks(draw):
    """Lines an artist would draw over a cage (the extremes of width and
    softness are test_random_scenes_match_reference's), with the edge
    angle, the classes a cage carries, the density fade, hidden lines and
    the thickness modes."""
    values = {
        "use_cage_edges": True,
        "thickness": draw(st.sampled_from([0.8, 1.5, 2.5])),
        "softness": draw(st.sampled_from([0.6, 1.0])),
        "diagonal_mode": draw(st.sampled_from(["HIDDEN", "SOLID", "DASHED"])),
        "edge_angle": draw(st.sampled_from([0.0, 0.0, 0.2, 0.6])),
        "use_backface_culling": draw(st.booleans()),
        "use_hidden_lines": draw(st.booleans()),
        "thickness_mode": draw(st.sampled_from(["PIXELS", "PIXELS", "WORLD", "DEPTH"])),
    }
    if draw(st.booleans()):
        values["use_density_fade"] = True
        values["density_fade_length"] = draw(st.sampled_from([6.0, 20.0]))
    for name in ("boundary", "sharp", "seam", "crease"):
        if draw(st.booleans()):
            values[f"use_{name}_edges"] = True
            values[f"{name}_thickness"] = draw(st.sampled_from([0.0, 2.5, 4.0]))
            values[f"{name}_pattern"] = draw(st.sampled_from(["SOLID", "DOTTED", "DASHED"]))
    return values


@st.composite
def orbits(draw):
    """Cameras that frame the mesh and its mirrored copies (build_stack)."""
    return {
        "location": scenes.orbit_location(
            draw(st.floats(5.0, 8.0)), draw(st.floats(0.0, 360.0)), draw(st.floats(-30.0, 60.0))
        ),
        "target": (0.0, 0.0, 0.0),
        "lens": draw(st.sampled_from([35.0, 50.0])),
    }


def build_stack(stack, line, camera):
    scene = scenes.empty_scene(*SIZE, world_thickness=0.02, thickness_depth_start=5.0, thickness_depth_end=10.0, **line)
    obj = SHAPES[stack["shape"]](scene)
    if "MIRROR" in stack["before"] + stack["after"]:
        # Off the mirror planes: a mirrored copy never lies on the original
        # (coplanar copies would leave which face shows to chance).
        obj.data.transform(Matrix.Translation((1.5, 1.5, 0.3)))
    marked = [bool((stack["marked"] >> (k % 16)) & 1) for k in range(len(obj.data.edges))]
    for k, edge in enumerate(obj.data.edges):
        edge.use_edge_sharp = marked[k] and k % 3 == 0
        edge.use_seam = marked[k] and k % 3 == 1
    crease = obj.data.attributes.new("crease_edge", "FLOAT", "EDGE")
    crease.data.foreach_set("value", [float(mark and k % 3 == 2) for k, mark in enumerate(marked)])
    settings = iter(zip(stack["variant"], stack["axes"]))
    for kind in stack["before"]:
        _add_modifier(obj, kind, *next(settings))
    subdivision = obj.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = stack["level"]
    subdivision.show_only_control_edges = stack["optimal_display"]
    for kind in stack["after"]:
        _add_modifier(obj, kind, *next(settings))
    scenes.add_camera(scene, **camera)
    return scene


def _add_modifier(obj, kind, variant: bool, axes):
    """A modifier of ``kind``; ``variant``: a Mirror or Array that merges, a
    Weld of connected vertices (else of all), a twist (else a bend)."""
    modifier = obj.modifiers.new(kind, kind)
    if kind == "BEVEL":
        modifier.width = 0.1
    elif kind == "SOLIDIFY":
        modifier.thickness = 0.1
    elif kind == "MIRROR":
        modifier.use_axis = [axis in axes for axis in range(3)]
        modifier.use_mirror_merge = variant
    elif kind == "ARRAY":
        modifier.count = 2
        modifier.relative_offset_displace = (1.2, 0.0, 0.0)
        modifier.use_merge_vertices = variant
    elif kind == "WELD":
        # Welding nothing (a weld that welds drops the cage: test_cage_edges_mask.py).
        modifier.merge_threshold = 1e-5
        modifier.mode = "CONNECTED" if variant else "ALL"
    elif kind == "SIMPLE_DEFORM":
        modifier.deform_method = "TWIST" if variant else "BEND"
        modifier.angle = 0.6
    elif kind == "DISPLACE":
        modifier.strength = 0.1


# Found by a hunt on bpy 5.3.0: a solidified Suzanne whose shells cross
# behind the surface, two faces 1.2e-7 of their depth apart at a sample
# where the visible wire has faded out (image model §7.2: one hidden layer
# or two is rounding's choice there).
FACES_LEVEL_BEHIND = dict(
    stack={
        "shape": "monkey",
        "before": ["SOLIDIFY"],
        "level": 1,
        "optimal_display": True,
        "after": [],
        "variant": [True],
        "axes": [(0,)],
        "marked": 1,
    },
    line={
        "use_cage_edges": True,
        "thickness": 0.8,
        "softness": 1.0,
        "diagonal_mode": "SOLID",
        "edge_angle": 0.6,
        "use_backface_culling": True,
        "use_hidden_lines": True,
        "thickness_mode": "PIXELS",
        "use_density_fade": True,
        "density_fade_length": 20.0,
        "use_sharp_edges": True,
        "sharp_thickness": 2.5,
        "sharp_pattern": "DASHED",
        "use_seam_edges": True,
        "seam_thickness": 2.5,
        "seam_pattern": "DASHED",
    },
    camera={"location": (-6.377686950159413, -2.808303737248412, 0.0), "target": (0.0, 0.0, 0.0), "lens": 35.0},
)


# Found by a hunt: a solidified tube whose top rim is seen nearly edge-on.
# One rim triangle is a sliver 2e-5 px thin on screen, hidden behind the
# tube's far wall; a pixel centre 1.4e-4 px beside it is covered, at the
# depth of the sliver's plane there (6.07, in front of the wall at 7.02),
# and shows the sliver's diagonal (image model §7.2: its face is rounding's
# choice there).
SLIVER_BESIDE = dict(
    stack={
        "shape": "tube",
        "before": ["SOLIDIFY"],
        "level": 2,
        "optimal_display": True,
        "after": [],
        "variant": [False],
        "axes": [(0,)],
        "marked": 6875,
    },
    line={
        "use_cage_edges": True,
        "thickness": 0.8,
        "softness": 0.6,
        "diagonal_mode": "SOLID",
        "edge_angle": 0.2,
        "use_backface_culling": False,
        "use_hidden_lines": False,
        "thickness_mode": "PIXELS",
        "use_density_fade": True,
        "density_fade_length": 6.0,
        "use_sharp_edges": True,
        "sharp_thickness": 4.0,
        "sharp_pattern": "SOLID",
        "use_seam_edges": True,
        "seam_thickness": 0.0,
        "seam_pattern": "SOLID",
        "use_crease_edges": True,
        "crease_thickness": 2.5,
        "crease_pattern": "DOTTED",
    },
    camera={
        "location": (-0.9935639171015087, -7.255556107654022, 0.3301809734840923),
        "target": (0.0, 0.0, 0.0),
        "lens": 50.0,
    },
)


@FUZZ
@example(**FACES_LEVEL_BEHIND)
@example(**SLIVER_BESIDE)
@given(stack=cage_stacks(), line=cage_looks(), camera=orbits())
def test_random_modifier_stacks_under_cage_edges_match_reference(stack, line, camera, tmp_path_factory):
    """The cage found through any such stack, drawn with its regions, is the
    reference's: which edges the last subdivision's input had (numbered by
    the reference itself) and what the modifiers after it keep."""
    log.forget()
    scene = build_stack(stack, line, camera)
    with recipe_on_failure(f"stack={stack!r}\nsettings={line!r}\ncamera={camera!r}"):
        check(scene, tmp_path_factory.getbasetemp() / "fuzz_cage.exr")


@FUZZ
@example(**FACES_LEVEL_BEHIND)
@example(**SLIVER_BESIDE)
@given(stack=cage_stacks(), line=cage_looks(), camera=orbits())
def test_random_modifier_stacks_under_cage_edges_in_the_overlay(stack, line, camera):
    """The same in the viewport overlay's first redraw over Blender's Solid
    shading depth (drawn directly or deferred as the overlay decides; an
    orbit redraws this way at every frame), compared with the reference
    wherever that depth agrees with the model: where Blender draws a
    surface nearer than the model's (a back face, which Blender's Solid
    shading does not cull when SolidWire's Backface Culling is on) nothing
    of ours can show, nor where a surface of ours lies within the
    overlay's depth bias behind the visible one or on it, as in the
    overlay test of every line option."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    log.forget()
    ensure_gpu()
    scene = build_stack(stack, line, camera)
    with recipe_on_failure(f"stack={stack!r}\nsettings={line!r}\ncamera={camera!r}"):
        check_overlay(scene, SIZE)


@st.composite
def drags(draw):
    """A drag in the viewport: a few vertices of the object's own mesh
    pulled towards its middle (a negative pull pushes them out past the
    bounds) and lifted, by the same step at each of 2-4 redraws."""
    return {
        "vertices": draw(st.lists(st.integers(0, 10_000), min_size=1, max_size=4)),
        "pull": draw(st.sampled_from([0.05, 0.2, -0.1, draw(st.floats(-0.1, 0.2))])),
        "lift": draw(st.floats(-0.04, 0.04)),
        "steps": draw(st.integers(2, 4)),
    }


@FUZZ
@given(
    stack=cage_stacks(),
    line=cage_looks(),
    camera=orbits(),
    drag=drags(),
    fill=st.sampled_from([None, "FLAT", "STUDIO"]),
    smooth=st.booleans(),
    deferred=st.booleans(),
)
def test_random_drags_in_the_overlay_draw_what_a_fresh_frame_draws(stack, line, camera, drag, fill, smooth, deferred):
    """A drag of a few vertices under a modifier stack in the viewport
    overlay, each mesh drawn as the overlay decides or (``deferred``)
    recorded however sparse: every redraw of the drag keeps what the mesh's
    topology decides (regions, cage mask, the kept image outside what the
    move changed; image model §5.6), and its last one draws what a fresh
    frame of the moved mesh draws once kept, or drawn directly where that
    step extracted the mesh again (a quad split the other way): a frame
    drawn directly, as under hidden lines, blends its layers into
    Blender's 8-bit buffer one by one, its kept image once, and they
    differ by a rounding step or two.
    A fresh extraction centres the mesh anew where an edit keeps its
    centre (extract.reposition), so float32 may decide coverage
    differently within 2 pixels of a silhouette, and which of two lines of
    equal strength gives a pixel its colour (ReferenceResult
    .style_undecided); elsewhere no pixel differs by more than 1.5/255."""

    from solidwire_addon.blender import runtime
    from solidwire_addon.blender.gpu_context import ensure_gpu
    from solidwire_addon.core import passes
    from tests.test_overlay import silhouette_mask
    from tests.test_overlay_deferred import _draw

    log.forget()
    ensure_gpu()
    line = dict(line, use_fill=fill is not None, **({"fill_shading": fill} if fill else {}))
    with pytest.MonkeyPatch.context() as patch:
        if deferred:
            patch.setattr(passes, "OVERLAY_DEFERRED_MIN_DENSITY", 0.0)
        scene = build_stack(stack, line, camera)
        obj = next(o for o in scene.objects if o.type == "MESH")
        for polygon in obj.data.polygons:
            polygon.use_smooth = smooth
        runtime.mesh_cache.clear()

        def frame():
            return _draw(scene, [obj], size=SIZE)

        with recipe_on_failure(f"stack={stack!r}\nsettings={line!r}\ncamera={camera!r}\ndrag={drag!r}"):
            frame()
            frame()  # the image is kept from here on
            vertices = obj.data.vertices
            middle = sum((v.co for v in vertices), Vector()) / len(vertices)
            dragged = sorted({k % len(vertices) for k in drag["vertices"]})
            for _step in range(drag["steps"]):
                for k in dragged:
                    v = vertices[k]
                    v.co = middle + (v.co - middle) * (1.0 - drag["pull"]) + Vector((0.0, 0.0, drag["lift"]))
                obj.data.update()
                edited, edit_stats = frame()
            runtime.mesh_cache.clear()
            direct = frame()[0]
            kept = frame()[0]
            fresh = direct if edit_stats["meshes_extracted"] else kept
            ref = reference.render_reference(scene, size=SIZE)
            near_silhouette = silhouette_mask(np.where(np.isfinite(ref.depth), ref.depth, np.inf), radius=2)
            decided = ~near_silhouette & ~ref.on_silhouette & ~ref.style_undecided
            differs = (np.abs(edited - fresh) > 1.5 / 255).any(axis=2) & decided
            assert not differs.any(), f"{int(differs.sum())} pixels differ from a fresh frame"


@st.composite
def strand_curves(draw):
    """0-4 hair curves (poly, Catmull-Rom or Bezier, some cyclic) of 1-6
    points, some repeated or nearly so (zero-length segments), a few not
    drawable (NaN, Inf, 3e38), with radii
    from none to wider than the view, and 0-6 points of a point cloud of
    one radius (0 draws a dot of the line's width)."""
    curves, radii, types, cyclic, left, right = [], [], [], [], [], []
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from([strand_scenes.POLY, strand_scenes.CATMULL_ROM, strand_scenes.BEZIER]))
        points = [draw(point)]
        for _k in range(draw(st.integers(0, 5))):
            step = draw(st.sampled_from(["new"] * 8 + ["same", "same", "near", "near", "bad"]))
            if step == "same":
                points.append(points[-1])
            elif step == "bad":
                # Non-finite or past the coordinate limit (3e38: what
                # Blender stores for inf): the point is left out with the
                # segments that touch it, image model §2.1. (Not -2e19:
                # a curve through it passes points under the limit but
                # far past what float32 draws to a pixel, §2.1.)
                bad = list(draw(point))
                bad[draw(st.integers(0, 2))] = draw(st.sampled_from([math.nan, math.inf, -math.inf, 3.0e38]))
                points.append(tuple(bad))
            elif step == "near":
                points.append(tuple(p + draw(st.floats(-1e-4, 1e-4)) for p in points[-1]))
            else:
                points.append(draw(point))
        curves.append(points)
        radius = draw(st.sampled_from([0.0, 0.01, 0.05, 0.3, 3.0, draw(st.floats(0.0, 0.2))]))
        radii.append([radius * draw(st.sampled_from([1.0, 0.0, 0.5, 2.0])) for _p in points])
        types.append(kind)
        cyclic.append(draw(st.booleans()) and len(points) > 2)
        for handles in (left, right):
            handles.extend(tuple(p + draw(st.floats(-0.5, 0.5)) for p in q) for q in points)
    return {
        "curves": curves,
        "radii": radii,
        "types": types,
        "cyclic": cyclic,
        "handles": (left, right),
        "resolution": draw(st.sampled_from([1, 2, 5, 12])),
        "points": draw(st.lists(point, max_size=6)),
        "point_radius": draw(st.sampled_from([0.0, 0.02, 0.15, 0.5, draw(st.floats(0.0, 0.3))])),
    }


# A hair and point-cloud scene: build_strands' arguments.
STRAND_SCENES = dict(
    hair=strand_curves(), mesh=st.none() | polygons(), camera=cameras(), line=line_settings(), transform=transforms()
)


def strand_recipe(hair, mesh, camera, line, transform) -> str:
    return f"hair={hair!r}\nmesh={mesh!r}\ncamera={camera!r}\nsettings={line!r}\ntransform={transform!r}"


def build_strands(hair, mesh, camera, line, transform):
    """The hair object (under ``transform``) and point cloud of ``hair``,
    beside the random mesh (or none), seen by ``camera``."""
    scene = empty_fuzz_scene(line, transform)
    if hair["curves"]:
        obj = strand_scenes.hair(
            scene,
            "FuzzHair",
            hair["curves"],
            hair["radii"],
            types=hair["types"],
            resolution=hair["resolution"],
            handles=tuple(np.asarray(h, dtype=np.float64) for h in hair["handles"]),
        )
        obj.data.attributes.new("cyclic", "BOOLEAN", "CURVE").data.foreach_set("value", hair["cyclic"])
        obj.location, obj.rotation_euler, obj.scale = transform["location"], transform["rotation"], transform["scale"]
    if hair["points"]:
        strand_scenes.point_cloud(scene, "FuzzPoints", hair["points"], hair["point_radius"])
    if mesh is not None:
        add_fuzz_mesh(scene, mesh)
    scenes.add_camera(scene, **camera)
    return scene


@FUZZ
@given(**STRAND_SCENES)
def test_random_strands_and_points_match_reference(hair, mesh, camera, line, transform, tmp_path_factory):
    """Random hair curves and point clouds, beside a random mesh that may
    hide them, in the F12 render: every strand and disc as
    tests/support/strand_reference.py measures it (hair-and-points.md)."""
    log.forget()
    scene = build_strands(hair, mesh, camera, line, transform)
    with recipe_on_failure(strand_recipe(hair, mesh, camera, line, transform)):
        image = robustness.render_exr(scene, tmp_path_factory.getbasetemp() / "fuzz_strands.exr")
        assert np.isfinite(image).all(), "NaN/Inf pixels"
        ref = strand_reference.render_strand_reference(scene)
        report = strand_reference.error_report(image[..., 3].astype(np.float64), ref)
        accuracy.assert_accurate(report)


@FUZZ
@given(**STRAND_SCENES)
def test_random_strands_and_points_in_the_overlay(hair, mesh, camera, line, transform):
    """The same scenes in the viewport overlay's first redraw over Blender's
    Solid shading depth of the mesh. Left out: where two strands, or a
    strand and a point, or two points, or two segments of a strand that do
    not meet at a joint (so also any three) reach a sample ("over" and the
    render's largest weight differ there by design: only the two segments
    at a joint choose between them, docs/user/hair-and-points.md), and
    where the segments of a strand that reach it are not all visible (the
    overlay's choice at a joint cannot see the viewport's depth); and as in
    the meshes' overlay test, where
    Blender's depth decides rather than the model (image model §5.6) and
    where a strand or disc lies within the overlay's depth bias of the
    visible surface, in front or behind."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    log.forget()
    ensure_gpu()
    scene = build_strands(hair, mesh, camera, line, transform)
    with recipe_on_failure(strand_recipe(hair, mesh, camera, line, transform)):
        viewport = robustness.Viewport(W, H)
        _stats, alpha = viewport.draw(scene)
        assert np.isfinite(alpha).all(), "NaN/Inf pixels"
        mesh_ref = reference.render_reference(scene, depth_layers=True)
        ref = strand_reference.render_strand_reference(scene, mesh=mesh_ref)
        tied = viewport.within_bias(mesh_ref.depth, ref.depth) & viewport.within_bias(ref.depth, mesh_ref.depth)
        partly_hidden = (ref.reached_any > 1) & (ref.reached < ref.reached_any)
        ref.on_silhouette |= (
            viewport.blender_decides(mesh_ref)
            | tied
            | (ref.groups > 1)
            | ref.apart
            | (ref.reached_any > 2)
            | partly_hidden
        )
        accuracy.assert_accurate(strand_reference.error_report(alpha, ref))


# Tessellated sources (image model §3.9): text, curves with a fill, an
# extrusion or a bevel, NURBS surfaces and metaballs, drawn as their
# outlines and profiles (or, with Tessellation, every edge).
@st.composite
def tessellated_sources(draw):
    """A text, curve, metaball or NURBS surface primitive, as
    add_tessellated_source builds it."""
    kind = draw(st.sampled_from(["FONT", "CURVE", "META", "SURFACE"]))
    source = {
        "kind": kind,
        "resolution": draw(st.sampled_from([1, 2, 4, 12])),
        "extrude": draw(st.sampled_from([0.0, 0.0, 0.05, 0.3, draw(st.floats(0.0, 0.5))])),
        "bevel_depth": draw(st.sampled_from([0.0, 0.0, 0.02, 0.1, draw(st.floats(0.0, 0.2))])),
        "bevel_resolution": draw(st.integers(0, 4)),
        "show_tessellation": draw(st.booleans()),
    }
    if kind == "FONT":
        # Letters with holes, dots, sharp and round corners; line breaks.
        source["body"] = draw(st.text(alphabet="AaBbOo08@#!.,:;ilWMg&%$ \n", min_size=1, max_size=5))
        source["size"] = draw(st.floats(0.3, 3.0))
        source["shear"] = draw(st.sampled_from([0.0, 0.0, 0.3, -0.5]))
        source["offset"] = draw(st.sampled_from([0.0, 0.0, 0.02, -0.02]))
    elif kind == "CURVE":
        source["points"] = [draw(point) for _ in range(draw(st.integers(2, 6)))]
        source["flat"] = draw(st.booleans())
        source["cyclic"] = draw(st.booleans())
        source["spline"] = draw(st.sampled_from(["BEZIER", "POLY", "NURBS"]))
        # The first of the list valid for the dimensions if this one is not.
        source["fill_mode"] = draw(st.sampled_from(["FULL", "BACK", "FRONT", "HALF", "BOTH", "NONE"]))
        source["handles"] = draw(st.sampled_from(["AUTO", "VECTOR", "ALIGNED"]))
    elif kind == "META":
        element = st.tuples(
            point, st.floats(0.2, 1.5), st.sampled_from(["BALL", "CAPSULE", "PLANE", "ELLIPSOID", "CUBE"])
        )
        source["elements"] = draw(st.lists(element, min_size=1, max_size=3))
        source["meta_resolution"] = draw(st.sampled_from([0.1, 0.2, 0.4]))
    else:
        source["surface"] = draw(st.sampled_from(["torus", "sphere", "cylinder", "surface", "curve", "circle"]))
    return source


def add_tessellated_source(scene, source):
    """The object "FuzzSource" of ``source`` (tessellated_sources) in ``scene``."""
    kind = source["kind"]
    if kind == "SURFACE":
        before = set(bpy.data.objects)
        getattr(bpy.ops.surface, f"primitive_nurbs_surface_{source['surface']}_add")()
        obj = next(o for o in bpy.data.objects if o not in before)
        for collection in list(obj.users_collection):
            collection.objects.unlink(obj)
        scene.collection.objects.link(obj)
        obj.name = "FuzzSource"
        obj.data.resolution_u = obj.data.resolution_v = source["resolution"]
        return obj
    if kind == "META":
        data = bpy.data.metaballs.new("FuzzSource")
        data.resolution = data.render_resolution = source["meta_resolution"]
        for co, radius, element_type in source["elements"]:
            element = data.elements.new(type=element_type)
            element.co, element.radius = co, radius
    else:
        data = bpy.data.curves.new("FuzzSource", kind)
        data.resolution_u, data.render_resolution_u = source["resolution"], 0
        data.extrude, data.bevel_depth = source["extrude"], source["bevel_depth"]
        data.bevel_resolution = source["bevel_resolution"]
        if kind == "FONT":
            data.body, data.size = source["body"], source["size"]
            data.shear, data.offset = source["shear"], source["offset"]
        else:
            _add_spline(data, source)
    obj = bpy.data.objects.new("FuzzSource", data)
    scene.collection.objects.link(obj)
    return obj


def _add_spline(curve, source):
    curve.dimensions = "2D" if source["flat"] else "3D"
    modes = ("NONE", "BACK", "FRONT", "BOTH") if source["flat"] else ("FULL", "BACK", "FRONT", "HALF")
    curve.fill_mode = source["fill_mode"] if source["fill_mode"] in modes else modes[0]
    points = [(x, y, 0.0) if source["flat"] else (x, y, z) for x, y, z in source["points"]]
    spline = curve.splines.new(source["spline"])
    if source["spline"] == "BEZIER":
        spline.bezier_points.add(len(points) - 1)
        for bezier_point, co in zip(spline.bezier_points, points):
            bezier_point.co = co
            bezier_point.handle_left_type = bezier_point.handle_right_type = source["handles"]
    else:
        spline.points.add(len(points) - 1)
        for spline_point, co in zip(spline.points, points):
            spline_point.co = (*co, 1.0)
    spline.use_cyclic_u = source["cyclic"]


def build_tessellated(source, camera, line, transform):
    """``source`` under ``transform``, seen by ``camera`` moved by the centre
    of the object's bounds (text runs along +x from its origin, surfaces and
    metaballs are of any size: aimed at the origin, most would miss; the
    printed recipe's camera is the one before the move)."""
    scene = empty_fuzz_scene(line, transform)
    scene.solidwire.show_tessellation = source["show_tessellation"]
    obj = add_tessellated_source(scene, source)
    obj.location, obj.rotation_euler, obj.scale = transform["location"], transform["rotation"], transform["scale"]
    bpy.context.view_layer.update()
    corners = [obj.matrix_world @ Vector(corner) for corner in obj.bound_box]
    # (A Bézier point whose handles lie on it evaluates to NaN: Blender's
    # bounds are then NaN too, and the camera aims at the origin.)
    corners = [corner for corner in corners if all(map(math.isfinite, corner))]
    centre = sum(corners, Vector()) / len(corners) if corners else Vector()
    moved = {key: tuple(a + b for a, b in zip(camera[key], centre)) for key in ("location", "target")}
    scenes.add_camera(scene, **{**camera, **moved})
    return scene


# A tessellated source's scene: build_tessellated's arguments, with the
# line options of the meshes' richest set (their edge marks apart: these
# objects have no mesh of their own to mark).
TESSELLATED_SCENES = dict(source=tessellated_sources(), camera=cameras(), line=rich_settings(), transform=transforms())


# Found by a hunt on bpy 5.3.0: a bevelled triangle curve whose third ring
# Blender evaluated to NaN and infinite coordinates; the coplanar rule
# (image model §3.9) read Blender's +Z for the dropped faces on it and hid
# the edge one of them shares with a drawn face lying flat under +Z.
CURVE_BESIDE_DROPPED = dict(
    source={
        "kind": "CURVE",
        "resolution": 1,
        "extrude": 1.9328731391964418e-194,
        "bevel_depth": 0.02,
        "bevel_resolution": 1,
        "show_tessellation": False,
        "points": [
            (-1.401298464324817e-45, 1.6653959412171826, 2.220446049250313e-16),
            (2.0622450233799018e-172, 0.029668260823734638, -0.33317195672959565),
            (-3.4753035248034332e-258, -1.8259905546988302e-11, 1.175494351e-38),
        ],
        "flat": True,
        "cyclic": True,
        "spline": "BEZIER",
        "fill_mode": "FULL",
        "handles": "VECTOR",
    },
    camera={
        "location": (-3.630036916211111, 1.1120141012842233, 0.45841517889634553),
        "target": (0.9999999999999999, 0.8822456811550672, 0.45841517889634553),
        "lens": 59.079095572082046,
        "ortho_scale": None,
        "shift": (-0.21307441545225678, -0.24638447363239815),
        "clip": (0.1, 20.0),
        "sensor_fit": "HORIZONTAL",
    },
    line={
        "thickness": 1.5,
        "softness": 0.25,
        "diagonal_mode": "SOLID",
        "use_backface_culling": True,
        "use_fade": False,
        "fade_start": 0.0028205880936081743,
        "fade_end": 14.107736277071647,
        "edge_angle": 3.0,
        "use_density_fade": True,
        "density_fade_length": 28.95588980346393,
        "thickness_mode": "PIXELS",
        "use_silhouettes": True,
        "use_seam_edges": True,
        "seam_thickness": 2.5,
        "seam_pattern": "DOTTED",
    },
    transform={
        "rotation": (-0.11716629018865587, -1.8129319562574666e-106, 1.0621057024197626e-110),
        "scale": (0.85, 0.6739697842030572, 1.24292924205019),
        "location": (2.548673151401123e-126, 0.31514649076528833, -1.401298464324817e-45),
        "pixel_aspect": 2.0,
    },
)


@FUZZ
@example(**CURVE_BESIDE_DROPPED)
@given(**TESSELLATED_SCENES)
def test_random_tessellated_sources_match_reference(source, camera, line, transform, tmp_path_factory):
    """Random text, curves, metaballs and NURBS surfaces in the F12 render,
    against the reference of their evaluated meshes under §3.9."""
    line = without_marks(line)
    log.forget()
    scene = build_tessellated(source, camera, line, transform)
    with recipe_on_failure(scene_recipe(camera, line, transform, source=source)):
        check(scene, tmp_path_factory.getbasetemp() / "fuzz_tessellated.exr")


@FUZZ
@given(**TESSELLATED_SCENES)
def test_random_tessellated_sources_in_the_overlay(source, camera, line, transform):
    """The same scenes in the overlay's first redraw, over Blender's Solid
    shading depth of the objects' tessellation, as the meshes' overlay test
    compares them."""
    from solidwire_addon.blender.gpu_context import ensure_gpu

    line = without_marks(line)
    log.forget()
    ensure_gpu()
    scene = build_tessellated(source, camera, line, transform)
    with recipe_on_failure(scene_recipe(camera, line, transform, source=source)):
        check_overlay(scene)
