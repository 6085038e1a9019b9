"""The package's layering, read from its source: no import cycles (module- or
function-level imports alike), nothing in ``core`` that imports Blender's
modules or reads Blender's data, front ends imported only by what presents
them, core's GPU-free modules and tests/pure/ without Blender, no private
names used across modules, a shader parameter block that is exactly the
schema's, one module map in the manual that lists every module, one
formatter for errors as one line, one table of render passes, one
description of a draw's target from which its shader variant follows,
passes as units, and no switch kept in a core module.
"""

from __future__ import annotations

import ast
import dataclasses
import re
import subprocess
import sys
from pathlib import Path

import pytest

from solidwire_addon.core import schema, shaders
from solidwire_addon.core.settings import DrawSettings, pack_params

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "solidwire_addon"


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules() -> dict[str, ast.Module]:
    return {_module_name(p): ast.parse(p.read_text(encoding="utf-8")) for p in PACKAGE.rglob("*.py")}


def _resolve(module: str, node: ast.ImportFrom, is_package: bool) -> str:
    if node.level == 0:
        return node.module or ""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def import_graph() -> dict[str, set[str]]:
    """module -> the package modules it imports, anywhere in its body."""
    modules = _modules()
    packages = {name for name in modules if (PACKAGE.parent / name.replace(".", "/") / "__init__.py").exists()}
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, tree in modules.items():
        for node in ast.walk(tree):
            targets = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = _resolve(name, node, name in packages)
                targets = [
                    f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base for alias in node.names
                ]
            for target in targets:
                if target in modules and target != name:
                    graph[name].add(target)
    return graph


def _cycle(graph) -> list[str] | None:
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt) :] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_the_import_graph_has_no_cycle():
    graph = import_graph()
    # The package's own __init__ registers everything: leave it out, as its
    # submodules never import it (checked below).
    graph = {k: {v for v in vs if v != "solidwire_addon"} for k, vs in graph.items()}
    assert _cycle(graph) is None, " -> ".join(_cycle(graph))


def test_a_cycle_would_be_found():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_core_never_imports_the_blender_side():
    for module, imports in import_graph().items():
        if module.startswith("solidwire_addon.core"):
            upward = sorted(i for i in imports if not i.startswith("solidwire_addon.core"))
            assert not upward, f"{module} imports {upward}"


# The add-on's front ends and the only modules that may import them besides
# the package's __init__ (which registers them): a front end is where a
# dependency ends, so that no module pulls in the UI, the operators, the
# overlay, the render engine or the command line for a helper of theirs.
FRONT_END_IMPORTERS = {
    "blender.ui": set(),
    "blender.ops": {"blender.ui"},  # the panels show the operators
    "blender.ops_composite": set(),
    "blender.overlay": {"blender.ops"},  # the toggle operator shows and hides it
    "blender.engine": set(),
    "blender.cli": set(),
}


def test_front_ends_are_imported_only_by_what_presents_them():
    graph = import_graph()
    for front_end, allowed in FRONT_END_IMPORTERS.items():
        module = f"solidwire_addon.{front_end}"
        assert module in graph, module
        importers = {name.removeprefix("solidwire_addon.") for name, imports in graph.items() if module in imports}
        extra = importers - allowed - {"solidwire_addon"}
        assert not extra, f"{sorted(extra)} import {front_end}"


# Blender's data API, which core never touches: it takes the arrays that
# blender/mesh_reading.py (and the rest of blender/) read instead. Names of
# Blender mesh data and its bulk reads, then of objects, depsgraphs and
# data-blocks; none of them names anything of core's own.
BLENDER_DATA_NAMES = frozenset(
    {
        "vertices",
        "edges",
        "loops",
        "polygons",
        "loop_triangles",
        "loop_triangle_polygons",
        "polygon_normals",
        "vertex_normals",
        "corner_normals",
        "normals_domain",
        "attributes",
        "color_attributes",
        "uv_layers",
        "shape_keys",
        "calc_loop_triangles",
        "foreach_get",
        "foreach_set",
        # ``data``: an object's mesh (``obj.data``), an attribute's values
        # (``attribute.data``).
        "data",
        "evaluated_get",
        "evaluated_depsgraph_get",
        "object_instances",
        "original",
        "to_mesh",
        "to_mesh_clear",
        "matrix_world",
        "material_slots",
        "modifiers",
        "session_uid",
        "as_pointer",
        "bound_box",
        "bl_rna",
        "rna_type",
    }
)
# Blender's Python modules besides ``gpu`` (which core draws with).
BLENDER_MODULES = frozenset({"bpy", "bmesh", "bpy_extras", "mathutils"})
# Ways to reach an attribute by its name as a string.
BY_NAME = frozenset({"getattr", "hasattr", "setattr", "delattr", "attrgetter", "methodcaller", "__getattribute__"})


def _called_name(call: ast.Call) -> str:
    func = call.func
    return func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""


def _docstrings(tree: ast.Module) -> set[int]:
    kinds = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
    return {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, kinds) and node.body and isinstance(node.body[0], ast.Expr)
    }


def blender_data_access(tree: ast.Module) -> list[str]:
    """Where ``tree`` reaches into Blender: an import of one of Blender's
    modules, or its name as a string anywhere but in a docstring
    (``__import__("bpy")``, ``sys.modules["bpy"]``); an attribute of
    Blender's data API (``mesh.polygons``, ``attribute.data.foreach_get``);
    or such an attribute asked for by name (``getattr(mesh, "polygons")``,
    ``attrgetter("data.polygons")``)."""
    docstrings = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [
                f"line {node.lineno}: import {a.name}" for a in node.names if a.name.split(".")[0] in BLENDER_MODULES
            ]
        elif (
            isinstance(node, ast.ImportFrom)
            and node.level == 0
            and (node.module or "").split(".")[0] in BLENDER_MODULES
        ):
            found.append(f"line {node.lineno}: from {node.module} import")
        elif isinstance(node, ast.Attribute) and node.attr in BLENDER_DATA_NAMES:
            found.append(f"line {node.lineno}: .{node.attr}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            if node.value.split(".")[0] in BLENDER_MODULES:
                found.append(f"line {node.lineno}: {node.value!r}")
        elif isinstance(node, ast.Call) and _called_name(node) in BY_NAME:
            for arg in node.args:
                value = arg.value if isinstance(arg, ast.Constant) and isinstance(arg.value, str) else ""
                if any(part in BLENDER_DATA_NAMES for part in value.split(".")):
                    found.append(f"line {node.lineno}: {_called_name(node)}({value!r})")
    return found


def test_core_reads_no_blender_data():
    """core takes numpy arrays and plain dataclasses and draws with ``gpu``:
    no module of it imports ``bpy`` (so no bpy.types, bpy.context or bpy.ops)
    or reads a Blender mesh, object or depsgraph (blender/mesh_reading.py
    does)."""
    for name, tree in _modules().items():
        if name.startswith("solidwire_addon.core"):
            found = blender_data_access(tree)
            assert not found, f"{name} reads Blender data: {found}"


@pytest.mark.parametrize(
    "source",
    [
        "import bpy",
        "import bpy.types as t",
        "from bpy.types import Mesh",
        "import bmesh",
        "from mathutils import Matrix",
        "bpy = __import__('bpy')",
        "importlib.import_module('bpy.utils')",
        "bpy = sys.modules['bpy']",
        "n = len(mesh.polygons)",
        "mesh.attributes.get('position')",
        "attribute.data.foreach_get('value', out)",
        "tris = mesh.loop_triangles",
        "mesh.polygon_normals",
        "obj.evaluated_get(depsgraph).data",
        "obj.matrix_world",
        "faces = getattr(mesh, 'polygons')",
        "read = operator.attrgetter('loop_triangles')",
        "read = operator.attrgetter('data.polygons')",
        "mesh.__getattribute__('polygons')",
        "hasattr(mesh, 'foreach_get')",
    ],
)
def test_blender_data_access_is_found(source):
    assert blender_data_access(ast.parse(source)), source


def test_plain_array_code_is_not_taken_for_blender_data():
    source = """
import numpy as np
from .extract import MeshArrays
def f(arrays, corner_vert, face_offsets, settings, name):
    \"\"\"bpy.types.Mesh is read on the Blender side; this takes its arrays.\"\"\"
    sizes = np.diff(face_offsets)
    getattr(settings, f"use_{name}_edges")
    return arrays.triangles[:, :3], arrays.triangle_polygons, arrays.vertex_count, {"edges": sizes}
"""
    assert blender_data_access(ast.parse(source)) == []


def _needs_gpu(graph) -> set[str]:
    """Modules that import ``gpu``, directly or through another module."""
    direct = {
        name
        for name, tree in _modules().items()
        for node in ast.walk(tree)
        if (isinstance(node, ast.Import) and any(a.name.split(".")[0] == "gpu" for a in node.names))
        or (isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "gpu")
    }
    needs = set(direct)
    while True:
        more = {name for name, imports in graph.items() if imports & needs} - needs
        if not more:
            return needs
        needs |= more


def test_core_without_gpu_work_imports_where_there_is_no_blender():
    """Every core module that does no GPU work imports in a Python without
    Blender (bpy, bmesh, mathutils and gpu made unimportable; the package's
    own __init__, which registers the add-on with Blender, left out)."""
    graph = import_graph()
    pure = sorted(name for name in graph if name.startswith("solidwire_addon.core.") and name not in _needs_gpu(graph))
    assert {"solidwire_addon.core.extract", "solidwire_addon.core.edge_select", "solidwire_addon.core.schema"} <= set(
        pure
    )
    script = f"""
import importlib, sys, types
for blocked in ("bpy", "bmesh", "bpy_extras", "mathutils", "gpu"):
    sys.modules[blocked] = None  # import raises ImportError
package = types.ModuleType("solidwire_addon")
package.__path__ = [{str(PACKAGE)!r}]
sys.modules["solidwire_addon"] = package
for name in {pure!r}:
    importlib.import_module(name)
"""
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr


def test_the_pure_tests_run_without_blender():
    """tests/pure/ (extraction, edge selection and the overlay's rules on
    plain arrays) passes in a Python where Blender's modules cannot be
    imported: neither the tests nor the core modules they use, nor the
    package's __init__, start Blender."""
    script = f"""
import sys
for blocked in ("bpy", "bmesh", "bpy_extras", "mathutils", "gpu"):
    sys.modules[blocked] = None  # import raises ImportError
import pytest
sys.exit(pytest.main([{str(ROOT / "tests" / "pure")!r}, "-q", "-p", "no:cacheprovider", "-p", "no:randomly"]))
"""
    result = subprocess.run(
        [sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True, timeout=300, check=False
    )
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert " passed" in result.stdout


def test_no_private_name_is_used_across_modules():
    for name, tree in _modules().items():
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.level:
                private = [a.name for a in node.names if a.name.startswith("_") and a.name != "__version__"]
                assert not private, f"{name} imports private {private} from {node.module}"


def test_the_parameter_block_is_the_schemas():
    glsl = schema.param_block_glsl()
    members = re.findall(r"^\s*(vec4|float) (\w+);", glsl, re.MULTILINE)
    assert [name for _kind, name in members] == [m.glsl for m in schema.PARAM_BLOCK]
    floats = sum(4 if kind == "vec4" else 1 for kind, _name in members)
    assert floats == schema.PARAM_FLOATS and floats % 4 == 0  # std140: whole vec4s
    # Every vec4 comes before the first float: no std140 alignment holes.
    kinds = [kind for kind, _name in members]
    assert kinds == sorted(kinds, key=lambda k: k != "vec4")
    packed = pack_params(DrawSettings(), (0, 0, 640, 480))
    assert len(packed) == 4 * schema.PARAM_FLOATS
    # Each setting's slot holds its packed value.
    values = __import__("numpy").frombuffer(packed, dtype="float32")
    offset = 0
    for member in schema.PARAM_BLOCK:
        size = 4 if member.glsl_type == "vec4" else 1
        if member.setting is not None:
            expected = member.setting.param.pack(getattr(DrawSettings(), member.setting.name))
            assert values[offset : offset + size] == pytest.approx(expected if size == 4 else [expected]), member.glsl
        offset += size


def test_every_block_member_the_shaders_read_exists():
    sources = "".join(p.read_text(encoding="utf-8") for p in shaders.SHADER_DIR.glob("*.glsl"))
    sources += schema.style_lookup_glsl()  # generated GLSL the loader adds
    used = set(re.findall(r"\bparams\.(\w+)", sources))
    declared = {m.glsl for m in schema.PARAM_BLOCK}
    assert used <= declared, sorted(used - declared)
    unused = {m.glsl for m in schema.PARAM_BLOCK if m.setting is not None} - used
    assert not unused, f"settings packed but never read by a shader: {sorted(unused)}"


def test_a_new_setting_needs_only_a_schema_entry(monkeypatch):
    """What a new setting gets for free: a property, a preset key, a CLI
    option, a panel row and (with a param) a slot in the block."""
    from solidwire_addon.blender import cli, properties

    extra = schema.Setting(
        "example_width",
        schema.FLOAT,
        2.0,
        "Example Width",
        "An example",
        minimum=0.0,
        maximum=10.0,
        subtype="PIXEL",
        section="line",
        param=schema.Param("example_width"),
    )
    monkeypatch.setattr(schema, "SETTINGS", (*schema.SETTINGS, extra))
    group = properties.make_group(schema.SCENE)
    assert "example_width" in group.__annotations__
    assert "example_width" in {s.name for s in schema.preset_settings()}
    args = cli.build_parser().parse_args(["--example-width", "3"])
    assert args.example_width == 3.0
    assert any(m.glsl == "example_width" for m in schema._param_block())


def test_every_table_is_laid_out_as_fetch_texel_reads_it():
    """fetch_texel (shaders/common.glsl) finds texel i at
    (i & (2^TABLE_ROW_SHIFT - 1), i >> TABLE_ROW_SHIFT) without asking the
    texture's size: every table (cache.table_shape) is TABLE_WIDTH wide, or
    a single row when shorter."""
    from solidwire_addon.core import cache

    source = (shaders.SHADER_DIR / "common.glsl").read_text(encoding="utf-8")
    shift = int(re.search(r"#define TABLE_ROW_SHIFT (\d+)", source).group(1))
    assert cache.TABLE_WIDTH == 1 << shift
    for count in (0, 1, 7, 2048, 4095, 4096, 4097, 123_457, 10_000_000):
        width, height = cache.table_shape(count)
        assert width * height >= max(count, 1)
        assert width == cache.TABLE_WIDTH or height == 1
        last = max(count, 1) - 1
        assert (last & (width - 1) if width == cache.TABLE_WIDTH else last) < width and (last >> shift) < height


MODULE_MAP = ROOT / "docs" / "dev" / "architecture.md"


def test_the_module_map_lists_every_module():
    """docs/dev/architecture.md is the one module map (the package docstrings
    point to it): every module under solidwire_addon/ has a row there, named
    by its path inside the package (``core/passes.py``), and the map names no
    module that is gone."""
    text = MODULE_MAP.read_text(encoding="utf-8")
    modules = {p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*.py") if p.name != "__init__.py"}
    missing = sorted(m for m in modules if f"`{m}`" not in text)
    assert not missing, f"modules missing from {MODULE_MAP.relative_to(ROOT)}: {missing}"
    named = set(re.findall(r"`((?:core|blender)/\w+\.py)`", text))
    assert not named - modules, f"the module map names modules that do not exist: {sorted(named - modules)}"


def test_errors_are_made_one_line_by_one_function():
    """core.log.one_line is the one formatter of an exception as one line:
    its whitespace folded, its type's name when it has no text. No other
    module folds an exception's text by hand, and none puts an exception's
    raw text (which may span lines) after its type's name in a message."""
    from solidwire_addon.core.log import one_line

    assert one_line(OSError("cannot open\n  the file:\tdenied ")) == "cannot open the file: denied"
    assert one_line(KeyError()) == "KeyError"
    assert one_line(RuntimeError("  \n")) == "RuntimeError"
    by_hand = re.compile(r"""["']\s["']\.join\(str\(\w+\)\.split\(\)\)|__name__\}: \{(exc|error|e)\}""")
    for path in PACKAGE.rglob("*.py"):
        if path.name == "log.py" and path.parent.name == "core":
            continue
        source = path.read_text(encoding="utf-8")
        assert not by_hand.search(source), f"{path.relative_to(ROOT)} formats an error by hand: use core.log.one_line"


def test_render_passes_come_from_one_table():
    """core.schema.RENDER_PASSES is the one list of render passes: the
    engine's pass layout and switches, the panel's Blender switches, the pass
    names core/passes.py draws and the view layer settings all derive from it,
    and no other module spells a pass name out."""
    from types import SimpleNamespace

    import bpy

    from solidwire_addon.blender import engine, ui
    from solidwire_addon.core import passes

    table = schema.RENDER_PASSES
    names = tuple(p.name for p in table)
    assert len(set(names)) == len(names) and len({p.switch for p in table}) == len(table)
    assert engine.PASS_LAYOUT == {p.name: (p.channels, p.channel_ids, p.kind) for p in table}
    assert all(len(p.channel_ids) == p.channels for p in table)
    # SolidWire's own switches are exactly the view layer settings, in order.
    assert [s.name for s in schema.settings_in(schema.VIEW_LAYER)] == [p.switch for p in table if p.own]
    # Blender's own switches exist on a view layer, and the panel shows them all.
    assert ui.BLENDER_PASSES == tuple(p.switch for p in table if not p.own)
    assert set(ui.BLENDER_PASSES) <= set(bpy.types.ViewLayer.bl_rna.properties.keys())
    assert schema.EXTRA_PASSES == tuple(n for n in names if n != schema.DEPTH_PASS)
    for constant in (
        "WIRE_PASS",
        "HIDDEN_WIRE_PASS",
        "EDGE_DISTANCE_PASS",
        "NORMAL_PASS",
        "OBJECT_INDEX_PASS",
        "MATERIAL_INDEX_PASS",
    ):
        assert getattr(passes, constant) == getattr(schema, constant)
    # What a view layer asks for, read through the table.
    every = SimpleNamespace(
        **{p.switch: True for p in table if not p.own},
        solidwire=SimpleNamespace(**{p.switch: True for p in table if p.own}),
    )
    assert engine.passes_of(every) == names
    assert engine.extra_passes_of(every) == schema.EXTRA_PASSES
    none = SimpleNamespace(**{p.switch: False for p in table if not p.own})  # no SolidWire settings at all
    assert engine.passes_of(none) == ()
    # Nobody else spells a pass name out.
    spelled = set(names)
    for module in ("blender/engine.py", "blender/ui.py", "core/passes.py"):
        tree = ast.parse((PACKAGE / module).read_text(encoding="utf-8"))
        literals = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
        assert not literals & spelled, f"{module} spells out {sorted(literals & spelled)}: use core.schema"


def test_edge_classes_are_defined_once_and_the_shaders_lookups_follow():
    """The edge classes and their style order come from the schema: the
    edge selection's list, the shader's style count and its per-style
    lookups (generated, one case per class in order, each reading a block
    member that exists); no GLSL file spells a class's member itself."""
    from solidwire_addon.core import edge_select

    assert edge_select.EDGE_CLASSES == schema.EDGE_CLASS_NAMES
    assert schema.STYLE_COUNT == 1 + len(schema.EDGE_CLASS_NAMES)
    glsl = schema.style_lookup_glsl()
    members = {m.glsl for m in schema.PARAM_BLOCK}
    for suffix in ("half_thickness", "duty", "color"):
        cases = re.findall(rf"case (\d+): return params\.(\w+)_{suffix};", glsl)
        assert [(int(k), name) for k, name in cases] == [
            (k + 1, name) for k, name in enumerate(schema.EDGE_CLASS_NAMES)
        ]
        assert {f"{name}_{suffix}" for _k, name in cases} <= members
    assert shaders.edge_styles_source().startswith(glsl)
    for path in shaders.SHADER_DIR.glob("*.glsl"):
        text = path.read_text(encoding="utf-8")
        spelled = [name for name in schema.EDGE_CLASS_NAMES if f"params.{name}_" in text]
        assert not spelled, f"{path.name} reads {spelled} itself: use the generated lookups"


def test_sampler_slots_are_one_table():
    """Every sampler of the add-on's shaders is declared through the one
    table of slots (shaders.SAMPLERS), never with a literal slot; slots stay
    within the 16 texture units every backend offers a stage."""
    tree = ast.parse((PACKAGE / "core" / "shaders.py").read_text(encoding="utf-8"))
    direct = [
        node.lineno
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "sampler"
    ]
    assert len(direct) == 1, f"info.sampler called outside add_sampler at lines {direct}"
    declared = [
        node.args[1].value
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and node.func.id == "add_sampler"
        and isinstance(node.args[1], ast.Constant)
    ]
    assert set(declared) == set(shaders.SAMPLERS), set(declared) ^ set(shaders.SAMPLERS)
    assert all(0 <= slot < 16 for slot, _kind in shaders.SAMPLERS.values())


# -- the draw hub -------------------------------------------------------------


def _functions(tree: ast.Module) -> dict[str, ast.FunctionDef]:
    return {node.name: node for node in tree.body if isinstance(node, ast.FunctionDef)}


def _calls(node: ast.AST, name: str) -> list[ast.Call]:
    """Calls of ``name`` or ``<module>.name`` inside ``node``."""
    found = []
    for call in ast.walk(node):
        if isinstance(call, ast.Call):
            func = call.func
            if (isinstance(func, ast.Name) and func.id == name) or (
                isinstance(func, ast.Attribute) and func.attr == name
            ):
                found.append(call)
    return found


def test_a_draws_variant_follows_from_its_target_description_alone():
    """draw.DrawTarget is the one description of where and how a draw lands:
    draw.shader_variant(settings, target) is the only place in draw.py that
    makes a shader variant, draw() asks it once, and each field of the
    description either selects compiled code (the variant changes with it)
    or is GPU state / an input texture (the variant does not)."""
    from dataclasses import fields, replace

    import numpy as np

    from solidwire_addon.core import draw

    tree = ast.parse((PACKAGE / "core" / "draw.py").read_text(encoding="utf-8"))
    functions = _functions(tree)
    makers = [name for name, node in functions.items() if _calls(node, "ShaderVariant")]
    assert makers == ["shader_variant"], f"shader variants made outside draw.shader_variant: {makers}"
    assert len(_calls(functions["draw"], "shader_variant")) == 1
    # draw() takes the description and a few other arguments, not one
    # keyword per target feature.
    arguments = functions["draw"].args
    assert [a.arg for a in arguments.args + arguments.kwonlyargs] == [
        "items",
        "view",
        "settings",
        "target",
        "cull",
        "program",
    ]

    settings = DrawSettings()
    plain = draw.shader_variant(settings, draw.DrawTarget())
    assert draw.shader_variant(settings) == plain
    # Field -> (a value that differs from the default, what the variant says then).
    selects_code = {
        "depth_bias": (2.0**-18, lambda v: v.depth_bias == 2.0**-18),
        "linear_depth": (True, lambda v: v.linear_depth),
        "clip_planes": (np.zeros((6, 4)), lambda v: v.clip_planes),
        "display": (object(), lambda v: v.display_transform),
        "stage": (draw.RESOLVE, lambda v: v.resolve),
        "region_lines": (object(), lambda v: v.region_lines),
        "region_distance": (object(), lambda v: v.region_distance),
        "view_depth": (True, lambda v: v.write_view_depth),
        "aovs": (True, lambda v: v.write_aovs),
        "lines": (draw.HIDDEN_LINES, lambda v: v.hidden_pass),
        "wire_layer": (True, lambda v: v.wire_layer),
    }
    state_or_input = {
        "depth_test",
        "depth_write",
        "visibility",
        "triangle_ids_by_vertex",
        "line_distance",
        "record_depth",
        "scissor_window",  # what a partial redraw leaves out (region-lines runs, record blocks)
        "behind_tiles",  # what a peeled layer's record leaves out (record blocks)
        "region_layers",
        "peel_depth",
        "region_layers_peeled",
        "line_runs",
        "depth_only",  # the surface's own program with the colour masked: only its picks' pre-pass is left out
        "drop_lineless",  # which triangles a hidden-line draw leaves out (read back from its picks)
        "walk_scope",  # which draws share a walk-table pre-pass's picks
    }
    names = {f.name for f in fields(draw.DrawTarget)}
    assert names == set(selects_code) | state_or_input, "classify every DrawTarget field here"
    for name, (value, says) in selects_code.items():
        variant = draw.shader_variant(settings, replace(draw.DrawTarget(), **{name: value}))
        assert variant != plain and says(variant), name
    stage_only = {
        "triangle_ids_by_vertex",
        "line_distance",
        "record_depth",
        "region_layers",
        "peel_depth",
        "line_runs",
    }
    for name in state_or_input - stage_only - {"region_layers_peeled"}:
        value = {
            "depth_test": "GREATER",
            "depth_write": False,
            "visibility": object(),
            "scissor_window": (0, 0, 8, 8, 3.0),
            "behind_tiles": object(),
            "depth_only": True,
            "drop_lineless": True,
            "walk_scope": object(),
        }[name]
        assert draw.shader_variant(settings, replace(draw.DrawTarget(), **{name: value})) == plain, name
    # The visibility stage's numbering is compiled code of that stage only.
    record = draw.DrawTarget(stage=draw.VISIBILITY, linear_depth=True)
    numbered = draw.shader_variant(settings, replace(record, triangle_ids_by_vertex=True))
    assert numbered.triangle_ids_by_vertex and not draw.shader_variant(settings, record).triangle_ids_by_vertex
    # So is the region-lines stage's keeping of distances.
    lines = draw.DrawTarget(stage=draw.LINES)
    distances = draw.shader_variant(settings, replace(lines, line_distance=True))
    assert distances.line_distance and not draw.shader_variant(settings, lines).line_distance
    # And its drawing of the wire's runs without the edge classes' code.
    classed = replace(settings, use_sharp_edges=True)
    assert draw.shader_variant(classed, lines).edge_classes
    assert not draw.shader_variant(classed, replace(lines, line_runs=draw.WIRE_RUNS)).edge_classes
    # So is the resolve's writing of the record's depth (the overlay's
    # resolve straight into Blender's buffer).
    resolve = draw.DrawTarget(stage=draw.RESOLVE, depth_bias=2.0**-18)
    straight = draw.shader_variant(settings, replace(resolve, record_depth=object()))
    assert straight.record_depth and not draw.shader_variant(settings, resolve).record_depth
    # So are the hidden region layers' record (which triangles, behind which
    # depth) and the direct hidden-line pass that leaves them out.
    layers = draw.shader_variant(settings, replace(record, region_layers=True, peel_depth=object()))
    assert layers.region_layers and layers.peel_layer
    assert not (draw.shader_variant(settings, record).region_layers or draw.shader_variant(settings, record).peel_layer)
    hidden = draw.DrawTarget().hidden()
    assert draw.shader_variant(settings, hidden.hidden(region_layers_peeled=True)).region_layers_peeled
    assert not draw.shader_variant(settings, hidden).region_layers_peeled
    assert not draw.shader_variant(settings, replace(draw.DrawTarget(), record_depth=object())).record_depth
    # "No wire" is said once, by the description: the plan leaves the
    # settings' wire colour alone.
    from solidwire_addon.core import passes

    hidden = replace(settings, use_hidden_lines=True)
    (surface,) = [unit for unit in passes.plan(hidden) if isinstance(unit, passes.SurfacePass)]
    assert surface.settings.wire_color == hidden.wire_color and surface.wire is False


def test_every_pass_is_a_unit_that_runs_offscreen_and_over_the_viewport():
    """The plan is a tuple of pass units (passes.RenderPass), each with its
    own render and over_viewport steps; the two executors only walk it (no
    chain of ifs on a pass's kind)."""
    from solidwire_addon.core import passes

    tree = ast.parse((PACKAGE / "core" / "passes.py").read_text(encoding="utf-8"))
    functions = _functions(tree)
    for executor in ("render_passes", "draw_over_viewport"):
        assert not any(isinstance(node, ast.If) for node in ast.walk(functions[executor])), executor
    every_option = dataclasses.replace(
        DrawSettings(), use_hidden_lines=True, use_silhouettes=True, use_fill=True, wire_color=(1, 1, 1, 1)
    )
    units = passes.plan(every_option, strands=True)
    assert all(isinstance(unit, passes.RenderPass) for unit in units)
    assert [type(unit).__name__ for unit in units] == [
        "RegionLinesPass",
        "SurfacePass",
        "HiddenLinesPass",
        "WirePass",
        "OutputsPass",
        "SilhouettePass",
        "StrandsPass",
    ]
    plain = passes.plan(DrawSettings())
    assert [type(unit).__name__ for unit in plain] == ["RegionLinesPass", "SurfacePass", "OutputsPass"]


def _bool_annotation(node) -> bool:
    return isinstance(node, ast.AnnAssign) and "bool" in ast.unparse(node.annotation)


def test_core_has_no_module_level_switches():
    """How a frame is drawn comes down from the caller as one frozen
    options.DrawOptions, never from a switch kept in a core module: no core
    module binds a name to True/False (or annotates one bool) at module
    level, no core function rebinds a public module-level name (``global``),
    and no module of the package assigns to an attribute of a core module."""
    from dataclasses import fields

    from solidwire_addon.core.options import DrawOptions

    modules = _modules()
    for name, tree in modules.items():
        if not name.startswith("solidwire_addon.core"):
            continue
        for node in tree.body:
            value = getattr(node, "value", None)
            is_bool = isinstance(value, ast.Constant) and isinstance(value.value, bool)
            assert not (isinstance(node, (ast.Assign, ast.AnnAssign)) and (is_bool or _bool_annotation(node))), (
                f"{name} keeps a module-level switch: {ast.unparse(node)}"
            )
        for node in ast.walk(tree):
            if isinstance(node, ast.Global):
                public = [n for n in node.names if not n.startswith("_")]
                assert not public, f"{name} rebinds module-level {public}"
    core_modules = {m.rsplit(".", 1)[1] for m in modules if m.startswith("solidwire_addon.core.")}
    for name, tree in modules.items():
        aliases = set()
        in_core = name.startswith("solidwire_addon.core")
        for node in ast.walk(tree):
            # ``from ..core import passes`` or, inside core, ``from . import passes``.
            if isinstance(node, ast.ImportFrom) and (
                "core" in (node.module or "").split(".") or (node.module is None and in_core)
            ):
                aliases |= {a.asname or a.name for a in node.names if a.name in core_modules}
        for node in ast.walk(tree):
            if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for target in targets:
                    assert not (
                        isinstance(target, ast.Attribute)
                        and isinstance(target.value, ast.Name)
                        and target.value.id in aliases
                    ), f"{name} sets {ast.unparse(target)} from a distance"
    assert DrawOptions.__dataclass_params__.frozen
    assert all(f.default is not dataclasses.MISSING for f in fields(DrawOptions)), "every option has a default"
