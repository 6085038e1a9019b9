"""Edits under the angle threshold (image model §3.4): a move of vertices is
checked against what the extraction kept, recomputing only the edges next
to a face that turned. While every edge stays on its side of the angle the
mesh is repositioned (positions uploaded, its drawn edges and regions
kept); when one crosses it, the mesh is extracted again. Either way the
result is what a full extraction of the moved mesh gives: the same tables
and the same image."""

from __future__ import annotations

import math

import bmesh
import bpy
import numpy as np
import pytest

import solidwire_addon
from solidwire_addon.blender import mesh_reading, overlay, runtime
from solidwire_addon.blender.views import camera_view
from solidwire_addon.core import edge_select
from tests.support import accuracy, reference, scenes

ANGLE = math.radians(6.0)


# -- the incremental test against the full one (no Blender) ----------------------------


def _grid_topology(n: int):
    """(corner_edge, face_offsets, edge count, corner_vert) of an n x n grid
    of quads, built with numpy."""
    ids = np.arange((n + 1) * (n + 1)).reshape(n + 1, n + 1)
    quads = np.stack([ids[:-1, :-1], ids[:-1, 1:], ids[1:, 1:], ids[1:, :-1]], axis=-1).reshape(-1, 4)
    pairs = np.stack([quads, np.roll(quads, -1, axis=1)], axis=-1).reshape(-1, 2)
    keys = np.sort(pairs, axis=1)
    unique, corner_edge = np.unique(keys[:, 0] * len(ids.ravel()) + keys[:, 1], return_inverse=True)
    offsets = np.arange(0, 4 * len(quads) + 1, 4)
    return corner_edge.ravel(), offsets, len(unique), quads


@pytest.mark.parametrize("seed", range(6))
def test_still_flat_answers_as_the_full_test(seed):
    rng = np.random.default_rng(seed)
    corner_edge, offsets, edge_count, quads = _grid_topology(24)
    normals = rng.normal(0.0, 0.15, (len(quads), 3)).astype(np.float32)
    normals[:, 2] = 1.0
    state = edge_select.EdgeAngleState(corner_edge, offsets, normals, edge_count, ANGLE)
    assert np.array_equal(state.flat, edge_select.flat_edges(corner_edge, offsets, normals, edge_count, ANGLE))
    assert 0 < state.flat.sum() < edge_count
    for _ in range(20):
        moved = normals.copy()
        turned = rng.choice(len(quads), size=rng.integers(1, 12), replace=False)
        moved[turned] += rng.normal(0.0, rng.choice([1e-4, 0.05, 0.3]), (len(turned), 3)).astype(np.float32)
        full = edge_select.flat_edges(corner_edge, offsets, moved, edge_count, ANGLE)
        before = state.flat.copy()
        kept = state.still_flat(moved)
        assert kept == np.array_equal(full, before)
        if kept:
            normals = moved  # the state now holds the moved normals
            assert np.array_equal(state.normals, moved)
        else:
            state = edge_select.EdgeAngleState(corner_edge, offsets, moved, edge_count, ANGLE)
            normals = moved


# -- through the render engine ------------------------------------------------------------


def _smooth_blob(scene):
    """A smooth, dense mesh (an ico sphere squashed into a blob, ~5k faces)
    whose dihedral angles spread around the threshold."""

    def build(bm):
        bmesh.ops.create_icosphere(bm, subdivisions=4, radius=1.0)
        for v in bm.verts:
            v.co.x *= 1.3 + 0.4 * math.sin(3.0 * v.co.z)
            v.co.z *= 0.7

    obj = scenes.mesh_object(scene, "Blob", build, rotation=(0.3, 0.1, 0.4))
    scenes.add_camera(scene, location=(2.5, -4.0, 2.0), target=(0.0, 0.0, 0.0))
    return obj


def _scene():
    scene = scenes.empty_scene(200, 150, edge_angle=ANGLE, thickness=1.5)
    return scene, _smooth_blob(scene)


def _flat_now(mesh):
    verts, corner_edge = mesh_reading.read_edge_topology(mesh)
    return edge_select.flat_edges(
        corner_edge, mesh_reading.read_face_offsets(mesh), mesh_reading.read_face_normals(mesh), len(verts), ANGLE
    )


def _render(scene, output_dir, name):
    rgba = scenes.render_to_file(scene, output_dir / f"{name}.png")
    meshes = runtime.mesh_cache.meshes()
    assert len(meshes) == 1
    return rgba, solidwire_addon.stats(), meshes[0]


def _tables(entry) -> dict:
    """What a GPU mesh draws from, in mesh space (positions made absolute:
    a repositioned mesh keeps its first centre)."""
    return {
        "edge flags": np.asarray(entry.edge_flags_cpu),
        "blocks": np.asarray(entry.triangles_cpu)[:, 3],
        "region lines": entry._region_lines_cpu,
        "triangle regions": entry._triangle_regions_cpu,
        "positions": np.asarray(entry._local_positions, np.float64) + entry.centre,
    }


def _assert_same_as_a_full_extraction(scene, entry, image, output_dir, name):
    runtime.mesh_cache.clear()
    cold_image, stats, cold = _render(scene, output_dir, f"{name}_cold")
    assert stats["meshes_extracted"] == 1
    warm, fresh = _tables(entry), _tables(cold)
    for key in ("edge flags", "blocks", "region lines", "triangle regions"):
        a, b = warm[key], fresh[key]
        assert (a is None) == (b is None) and (a is None or np.array_equal(a, b)), key
    assert np.allclose(warm["positions"], fresh["positions"], atol=1e-5)
    diff = reference._statistics(np.abs(image - cold_image).max(axis=-1).ravel())
    accuracy.assert_accurate({**diff, "nan": int(np.isnan(image).sum())})


def _move(mesh, ids, offsets):
    positions = mesh_reading.read_positions(mesh).astype(np.float64)
    positions[ids] += offsets
    mesh.vertices.foreach_set("co", positions.astype(np.float32).ravel())
    mesh.update()


def test_moving_one_vertex_keeps_the_drawn_edges(output_dir):
    scene, obj = _scene()
    mesh = obj.data
    _render(scene, output_dir, "angle_edit_before")
    before = _flat_now(mesh)
    _move(mesh, [17], np.array([[0.0, 0.0, 2e-3]]))
    assert np.array_equal(_flat_now(mesh), before), "the move keeps every edge on its side"
    image, stats, entry = _render(scene, output_dir, "angle_edit_one_vertex")
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    _assert_same_as_a_full_extraction(scene, entry, image, output_dir, "angle_edit_one_vertex")


@pytest.mark.parametrize("amplitude", [0.0003, 0.25])
def test_a_sculpt_like_move_of_one_percent_of_the_vertices(amplitude, output_dir):
    """A brush stroke: the 1 % of vertices nearest a point pushed along the
    normal with a smooth falloff. A light stroke keeps every edge on its
    side of the angle (repositioned), a strong one moves some across it
    (extracted again); the result is the full extraction's either way."""
    scene, obj = _scene()
    mesh = obj.data
    _render(scene, output_dir, "angle_sculpt_before")
    before = _flat_now(mesh)
    positions = mesh_reading.read_positions(mesh).astype(np.float64)
    centre = positions[np.argmax(positions[:, 0])]
    distance = np.linalg.norm(positions - centre, axis=1)
    count = max(1, len(positions) // 100)
    ids = np.argsort(distance)[:count]
    radius = distance[ids].max()
    falloff = (1.0 - (distance[ids] / radius) ** 2) ** 2
    normals = positions[ids] / np.linalg.norm(positions[ids], axis=1, keepdims=True)
    _move(mesh, ids, amplitude * falloff[:, None] * normals)
    crossed = not np.array_equal(_flat_now(mesh), before)
    assert crossed == (amplitude > 0.01), "the light stroke keeps the edges, the strong one does not"
    image, stats, entry = _render(scene, output_dir, f"angle_sculpt_{amplitude}")
    expected = (1, 0) if crossed else (0, 1)
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == expected
    _assert_same_as_a_full_extraction(scene, entry, image, output_dir, f"angle_sculpt_{amplitude}")


def test_repositioned_edit_matches_the_reference(output_dir):
    """After several light edits drawn by repositioning, the image still
    matches the float64 reference, which extracts nothing."""
    scene, obj = _scene()
    mesh = obj.data
    _render(scene, output_dir, "angle_edits_reference_first")
    for step, vertex in enumerate((5, 90, 400)):
        _move(mesh, [vertex], np.array([[0.0, 1e-3 * (step + 1), 0.0]]))
        _image, stats, _entry = _render(scene, output_dir, "angle_edits_reference")
        assert stats["meshes_repositioned"] == 1
    report = accuracy.measure(scene, "angle_edits_reference", output_dir)
    accuracy.assert_accurate(report)


def test_the_overlay_repositions_an_edit_and_draws_what_a_fresh_frame_draws():
    """In the viewport overlay (depsgraph update counters, not the content
    fingerprint): a light edit uploads positions only and draws exactly what
    a frame from a fresh extraction draws."""
    from tests.test_overlay import FakeViewport

    scene, obj = _scene()
    size = (200, 150)
    keep = overlay.viewport_object_filter(bpy.context.view_layer)

    def redraw():
        depsgraph = bpy.context.evaluated_depsgraph_get()
        view = camera_view(scene, depsgraph, size)
        viewport = FakeViewport(*size)
        stats = viewport.draw_overlay(depsgraph, view, scene.solidwire.snapshot(), object_filter=keep)
        return stats, viewport.rgba()

    redraw()
    before = _flat_now(obj.data)
    _move(obj.data, [42], np.array([[2e-4, 0.0, 0.0]]))
    assert np.array_equal(_flat_now(obj.data), before)
    stats, edited = redraw()
    assert (stats["meshes_extracted"], stats["meshes_repositioned"]) == (0, 1)
    runtime.mesh_cache.clear()
    stats, fresh = redraw()
    assert stats["meshes_extracted"] == 1
    assert np.array_equal(edited, fresh)


@pytest.mark.parametrize("seed", range(3))
def test_still_flat_among_candidates_answers_as_the_full_test_on_them(seed):
    """Beside a mask (the cage look) only the mask's edges are tested: the
    state's flat edges are the full test's among them, and a move is
    answered as the full test answers it on them alone."""
    rng = np.random.default_rng(seed)
    corner_edge, offsets, edge_count, quads = _grid_topology(24)
    candidates = rng.random(edge_count) < 0.3
    normals = rng.normal(0.0, 0.15, (len(quads), 3)).astype(np.float32)
    normals[:, 2] = 1.0
    state = edge_select.EdgeAngleState(corner_edge, offsets, normals, edge_count, ANGLE, candidates=candidates)
    full = edge_select.flat_edges(corner_edge, offsets, normals, edge_count, ANGLE)
    assert np.array_equal(state.flat, full & candidates)
    assert 0 < state.flat.sum() < (full.sum())
    for _ in range(20):
        moved = normals.copy()
        turned = rng.choice(len(quads), size=rng.integers(1, 12), replace=False)
        moved[turned] += rng.normal(0.0, rng.choice([1e-4, 0.05, 0.3]), (len(turned), 3)).astype(np.float32)
        now = edge_select.flat_edges(corner_edge, offsets, moved, edge_count, ANGLE) & candidates
        before = state.flat.copy()
        kept = state.still_flat(moved)
        assert kept == np.array_equal(now, before)
        normals = moved
        if not kept:
            state = edge_select.EdgeAngleState(corner_edge, offsets, moved, edge_count, ANGLE, candidates=candidates)
