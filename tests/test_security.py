"""Security: no network, no undeclared permissions, writes
only where the user asked (render output) and in its own user directory,
presets are data that is validated, never code that is run."""

from __future__ import annotations

import ast
import json
import os
import stat
import threading
import tomllib
from pathlib import Path

import bpy
import pytest

from solidwire_addon.blender import presets
from tests.support import robustness, scenes

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "solidwire_addon"
SOURCES = sorted(PACKAGE.rglob("*.py"))

# Modules an add-on that needs no network, no processes and no code loading
# has no business importing at run time.
FORBIDDEN_MODULES = {
    "socket",
    "ssl",
    "urllib",
    "urllib3",
    "requests",
    "http",
    "httpx",
    "aiohttp",
    "ftplib",
    "smtplib",
    "poplib",
    "imaplib",
    "telnetlib",
    "xmlrpc",
    "websocket",
    "websockets",
    "subprocess",
    "multiprocessing",
    "pty",
    "pickle",
    "marshal",
    "shelve",
    "ctypes",
    "webbrowser",
}
FORBIDDEN_CALLS = {"eval", "exec", "compile", "__import__", "execfile"}
# What each manifest permission is for, and the evidence of its use in code.
PERMISSION_EVIDENCE = {
    "network": FORBIDDEN_MODULES & {"socket", "urllib", "requests", "http", "ssl"},
    "clipboard": {"clipboard"},
    "camera": {"camera_capture"},
    "microphone": {"microphone"},
    # an operator that reads or writes a path the user picks
    "files": {'subtype="FILE_PATH"', "subtype='FILE_PATH'", 'subtype="DIR_PATH"', "fileselect_add"},
}


def _imports(tree) -> set[str]:
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
        elif isinstance(node, ast.Call):
            func = node.func
            dotted = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if dotted == "import_module" and node.args and isinstance(node.args[0], ast.Constant):
                names.add(str(node.args[0].value).split(".")[0])
    return names


def _calls(tree) -> set[str]:
    return {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}


def test_addon_sources_import_no_network_process_or_code_loading_modules():
    assert len(SOURCES) >= 5
    found = {}
    for path in SOURCES:
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        bad = (_imports(tree) & FORBIDDEN_MODULES) | (_calls(tree) & FORBIDDEN_CALLS)
        if bad:
            found[path.name] = sorted(bad)
    assert found == {}


def test_scanner_sees_a_forbidden_import():
    """The scan above can fail (a test that cannot fail is no test)."""
    tree = ast.parse(
        "import socket\nfrom urllib.request import urlopen\nimportlib.import_module('subprocess')\neval('1')"
    )
    assert {"socket", "urllib", "subprocess"} <= _imports(tree)
    assert "eval" in _calls(tree)


def test_loaded_addon_modules_hold_no_network_module():
    held = robustness.scan_module_state(
        lambda v: getattr(v, "__name__", "").split(".")[0] in FORBIDDEN_MODULES and type(v).__name__ == "module"
    )
    assert held == []


def test_manifest_declares_no_permission_it_does_not_use():
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text(encoding="utf-8"))
    declared = manifest.get("permissions", {})
    assert isinstance(declared, dict)
    text = "\n".join(p.read_text(encoding="utf-8") for p in SOURCES)
    # Blender's node-group API (`interface.new_socket`, a node socket) is not
    # a network socket; the imports above are the evidence for those.
    for node_api in ("new_socket", "socket_type"):
        text = text.replace(node_api, "node_api")
    imports = set().union(*(_imports(ast.parse(p.read_text(encoding="utf-8"))) for p in SOURCES))
    used = {
        permission
        for permission, evidence in PERMISSION_EVIDENCE.items()
        if (evidence & imports) or any(e in text for e in evidence)
    }
    assert set(declared) <= used, f"declared but unused: {sorted(set(declared) - used)}"
    assert used <= set(declared), f"used but undeclared: {sorted(used - set(declared))}"
    for reason in declared.values():  # Blender wants a short reason for each
        assert isinstance(reason, str) and 0 < len(reason) <= 64


def test_manifest_minimum_version_is_a_tested_version():
    """blender_version_min must be a version the compat run covers."""
    manifest = tomllib.loads((ROOT / "blender_manifest.toml").read_text(encoding="utf-8"))
    minimum = tuple(int(x) for x in manifest["blender_version_min"].split("."))
    compat = (ROOT / "scripts" / "compat.sh").read_text(encoding="utf-8")
    assert f"{minimum[0]}.{minimum[1]}." in compat, f"scripts/compat.sh does not test {minimum}"


def _tree_state(folder: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in folder.rglob("*") if "__pycache__" not in p.parts}


def test_writes_only_the_chosen_output_and_its_user_directory(tmp_path, monkeypatch):
    """A render, a preset saved and applied: the add-on folder is untouched
    (an upgrade replaces it), presets go to Blender's user folder, the image
    to the chosen path and nothing to the working directory."""
    monkeypatch.chdir(tmp_path)
    package_before = _tree_state(PACKAGE)
    cwd_before = set(tmp_path.iterdir())
    scene = scenes.empty_scene(32, 24)
    scenes.cube(scene)
    scenes.add_camera(scene)
    out = tmp_path / "chosen" / "frame.exr"
    robustness.render_exr(scene, out)
    saved = presets.save("Security Probe", scene.solidwire)
    try:
        bpy.ops.solidwire.preset_apply(name="Security Probe")
        user_root = Path(os.environ["BLENDER_USER_RESOURCES"]).resolve()
        assert user_root in saved.resolve().parents
        assert PACKAGE not in saved.resolve().parents
    finally:
        saved.unlink()
    assert _tree_state(PACKAGE) == package_before
    assert set(tmp_path.iterdir()) - cwd_before == {tmp_path / "chosen"}
    assert [p.name for p in (tmp_path / "chosen").iterdir()] == ["frame.exr"]


# ------------------------------------------------------------- hostile presets


MARKER = "solidwire_pwned_marker"


def _code(marker: Path) -> str:
    return f"__import__('os').system('touch {marker}')"


def _hostile(marker: Path) -> dict:
    code = _code(marker)
    document = {"solidwire_preset": 1, "name": "Hostile", "settings": {"thickness": 2.0}}
    return {
        "code as a number": json.dumps(document | {"settings": {"thickness": code}}),
        "code as a colour": json.dumps(document | {"settings": {"wire_color": code}}),
        "code as an enum": json.dumps(document | {"settings": {"diagonal_mode": code}}),
        "code as a key": json.dumps(document | {"settings": {code: 1.0}}),
        "python preset file": f"import os\nos.system('touch {marker}')\nbpy.context.scene.solidwire.thickness = 9\n",
        "dunder keys": json.dumps(document | {"__class__": "x", "settings": {"__dict__": {}}}),
        "deeply nested": '{"solidwire_preset": 1, "name": "Deep", "settings": {"thickness": '
        + "[" * 25_000
        + "]" * 25_000
        + "}}",
        "huge number": json.dumps(document).replace("2.0", "1" + "0" * 5000),
        "huge file": json.dumps(document | {"description": "y" * 70_000}),
        "wrong types everywhere": json.dumps({"solidwire_preset": "1", "name": ["x"], "settings": [1, 2]}),
        "not utf-8": b"\xff\xfe{\x00}".decode("latin-1"),
        "empty": "",
    }


@pytest.mark.parametrize("case", list(_hostile(Path("/x"))))
def test_hostile_preset_is_refused_and_nothing_runs_or_changes(case, tmp_path):
    marker = tmp_path / MARKER
    text = _hostile(marker)[case]
    path = tmp_path / "hostile.json"
    path.write_bytes(text.encode("latin-1") if case == "not utf-8" else text.encode("utf-8"))
    scene = scenes.empty_scene(32, 24)
    before = presets.values_of(scene.solidwire)
    with pytest.raises(presets.PresetError) as caught:
        preset = presets.load(path)
        presets.apply(preset, scene.solidwire)  # only reached if load accepted it
    message = str(caught.value)
    assert message.startswith("hostile.json: ") and "\n" not in message and len(message) < 1000
    assert presets.values_of(scene.solidwire) == before
    assert not marker.exists()


def test_code_in_a_name_is_only_text(tmp_path):
    """A valid preset whose name and description hold Python is loaded as
    text: nothing is evaluated."""
    marker = tmp_path / MARKER
    code = _code(marker)[:60]
    path = tmp_path / "named.json"
    path.write_text(
        json.dumps({"solidwire_preset": 1, "name": code, "description": _code(marker), "settings": {"thickness": 2.0}}),
        encoding="utf-8",
    )
    preset = presets.load(path)
    assert preset.name == code.strip()
    scene = scenes.empty_scene(32, 24)
    presets.apply(preset, scene.solidwire)
    assert scene.solidwire.thickness == 2.0
    assert not marker.exists()


def test_a_fifo_named_like_a_preset_does_not_hang(tmp_path):
    """Listing user presets must not block on a special file (a FIFO would
    wait for a writer forever and freeze Blender's menu)."""
    fifo = tmp_path / "trap.json"
    os.mkfifo(fifo)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    outcome = {}

    def load():
        try:
            presets.load(fifo)
        except presets.PresetError as exc:
            outcome["error"] = str(exc)

    worker = threading.Thread(target=load, daemon=True)
    worker.start()
    worker.join(timeout=5.0)
    if worker.is_alive():  # unblock the reader so the thread can finish
        with open(fifo, "w") as writer:
            writer.write("{}")
        worker.join(timeout=5.0)
        pytest.fail("presets.load() blocked on a FIFO")
    assert "error" in outcome and outcome["error"].startswith("trap.json: ")
