"""The extension as users get it: Blender's own validator and builder
(``blender_ext.py``, shipped in the bpy wheel) check the manifest and build
the zip; the zip is installed and enabled with
``bpy.ops.extensions.package_install_files`` in a fresh process (a private
``BLENDER_USER_RESOURCES``) and renders from there.

Installing in the test process would register the engine a second time, so
the install runs in a subprocess that reports back as JSON.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import bpy
import numpy as np
import pytest

from tests.support import scenes

ROOT = Path(__file__).resolve().parent.parent
BPY_SCRIPTS = Path(bpy.utils.resource_path("LOCAL")) / "scripts"
BLENDER_EXT = BPY_SCRIPTS / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
# The tag list Blender's own `blender --command extension build` validates against.
VALID_TAGS = BPY_SCRIPTS / "modules" / "_bpy_internal" / "extensions" / "tags.py"
TIMEOUT_S = 300

SHIPPED_FOLDERS = ("solidwire_addon", "shaders")
SHIPPED_TOP_LEVEL = {"blender_manifest.toml", "__init__.py", "LICENSE", *SHIPPED_FOLDERS}
NEVER_SHIPPED_PREFIXES = ("tests/", "scripts/", ".ci/", "docs/", ".venv/", "dist/", "out/", "build/", ".git/")


def blender_ext(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, str(BLENDER_EXT), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )


def test_blenders_tools_are_in_the_wheel():
    assert BLENDER_EXT.is_file(), BLENDER_EXT
    assert VALID_TAGS.is_file(), VALID_TAGS


def test_manifest_validates():
    result = blender_ext("validate", "--valid-tags", VALID_TAGS, ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "FATAL_ERROR" not in result.stdout + result.stderr


@pytest.fixture(scope="module")
def extension_zip(tmp_path_factory) -> Path:
    out_dir = tmp_path_factory.mktemp("dist")
    result = blender_ext("build", "--valid-tags", VALID_TAGS, "--source-dir", ROOT, "--output-dir", out_dir)
    assert result.returncode == 0, result.stdout + result.stderr
    (path,) = out_dir.glob("*.zip")
    assert path.name == "solidwire-0.1.0.zip"
    return path


def _shipped_source_files() -> set[str]:
    files = set()
    for folder in SHIPPED_FOLDERS:
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                files.add(path.relative_to(ROOT).as_posix())
    return files


def test_zip_holds_the_add_on_and_nothing_else(extension_zip):
    with zipfile.ZipFile(extension_zip) as archive:
        names = set(archive.namelist())
    for required in ("blender_manifest.toml", "__init__.py", "LICENSE"):
        assert required in names
    missing = _shipped_source_files() - names
    assert not missing, f"not in the zip: {sorted(missing)}"
    assert any(name.startswith("shaders/") and name.endswith(".glsl") for name in names)
    leaked = sorted(
        name
        for name in names
        if name.split("/")[0] not in SHIPPED_TOP_LEVEL
        or name.startswith(NEVER_SHIPPED_PREFIXES)
        or "__pycache__" in name
        or name.endswith((".pyc", ".blend1", ".zip"))
    )
    assert not leaked, f"development files in the zip: {leaked}"
    # The benchmark's published-method variants stay in the repository.
    bench_only = sorted(name for name in names if "methods" in name or "bench" in name)
    assert not bench_only, f"benchmark code in the zip: {bench_only}"


def test_built_zip_validates(extension_zip):
    result = blender_ext("validate", "--valid-tags", VALID_TAGS, extension_zip)
    assert result.returncode == 0, result.stdout + result.stderr


# Runs in a fresh process with the repository NOT on sys.path, so everything
# must come from the installed extension.
_INSTALL_AND_RENDER = textwrap.dedent(
    """
    import json, runpy, sys
    import bpy

    zip_path, repo_root, render_script, out_dir = sys.argv[1:5]
    report = {}

    def engine_registered():
        return any(getattr(c, "bl_idname", None) == "SOLIDWIRE" and c.is_registered
                   for c in bpy.types.RenderEngine.__subclasses__())

    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    report["modules"] = sorted(name for name in sys.modules if "solidwire" in name)
    report["engine"] = engine_registered()
    report["settings"] = hasattr(bpy.types.Scene, "solidwire")

    # A small scene in a new scene of the current file (reading factory
    # settings would reset the preferences and disable the extension).
    # Only the test helpers come from the repository (appended, so the
    # installed extension is what `solidwire` names resolve to).
    sys.path.append(repo_root)
    from tests.support import scenes
    scene = bpy.data.scenes.new("Packaged")
    scene.render.engine = "SOLIDWIRE"
    scene.render.resolution_x, scene.render.resolution_y = 80, 60
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.solidwire.wire_color = (1.0, 1.0, 1.0, 1.0)
    scenes.cube(scene)
    scenes.add_camera(scene)
    scenes.render_to_file(scene, out_dir + "/installed_cube.png", depth16=False)
    report["stats"] = sys.modules["bl_ext.user_default.solidwire"].stats()

    # The command line, Blender form, with the extension installed: it must
    # use the installed engine, not import the repository's copy.
    bpy.app.binary_path = "/opt/blender/blender"
    sys.argv = ["blender", "-b", "--python", render_script, "--", "--demo", "-o", out_dir + "/installed_demo.png"]
    runpy.run_path(render_script, run_name="__main__")
    report["repo_package_imported"] = "solidwire_addon" in sys.modules

    bpy.ops.preferences.addon_disable(module="bl_ext.user_default.solidwire")
    report["engine_after_disable"] = engine_registered()
    report["settings_after_disable"] = hasattr(bpy.types.Scene, "solidwire")
    print("REPORT " + json.dumps(report), flush=True)
    """
)


def test_zip_installs_enables_renders_and_disables(extension_zip, tmp_path, output_dir):
    env = dict(os.environ)
    env["BLENDER_USER_RESOURCES"] = str(tmp_path / "blender_user")
    env.pop("PYTHONPATH", None)
    for name in ("installed_cube.png", "installed_demo.png"):
        (output_dir / name).unlink(missing_ok=True)
    result = subprocess.run(
        [
            sys.executable,
            "-c",
            _INSTALL_AND_RENDER,
            str(extension_zip),
            str(ROOT),
            str(ROOT / "scripts" / "render.py"),
            str(output_dir),
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "SolidWire skips" not in result.stderr, result.stderr
    (line,) = [line for line in result.stdout.splitlines() if line.startswith("REPORT ")]
    report = json.loads(line[len("REPORT ") :])

    assert "bl_ext.user_default.solidwire" in report["modules"]
    assert "solidwire_addon" not in report["modules"], "the repository copy was imported"
    assert report["engine"] and report["settings"]
    assert report["stats"]["objects_drawn"] == 1 and report["stats"]["triangles_drawn"] == 12
    assert not report["repo_package_imported"]
    assert not report["engine_after_disable"] and not report["settings_after_disable"]
    assert (tmp_path / "blender_user" / "extensions" / "user_default" / "solidwire" / "blender_manifest.toml").is_file()

    cube = scenes.load_png(output_dir / "installed_cube.png")
    alpha = cube[..., 3]
    assert cube.shape == (60, 80, 4)
    assert np.count_nonzero(alpha > 0.5) > 50, "no wire pixels"
    assert alpha[0, 0] == 0.0 and alpha[-1, -1] == 0.0, "transparent film expected at the corners"
    demo = output_dir / "installed_demo.png"
    assert demo.is_file() and demo.stat().st_size > 0
    assert "rendered" in result.stdout
