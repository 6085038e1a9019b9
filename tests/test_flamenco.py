"""The Flamenco job type, scripts/farm/flamenco/solidwire.js.

Flamenco runs job scripts inside its Manager; here Node runs them instead,
through tests/flamenco_harness.js, which gives the script stand-ins for
Flamenco's ``author`` API and records the tasks and commands it authors. The
tests check those against the command lines the job type promises (see the
script's header and docs/user/render-farm.md). Nothing here needs Blender or the
add-on.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "farm" / "flamenco" / "solidwire.js"
HARNESS = ROOT / "tests" / "flamenco_harness.js"
NODE = shutil.which("node")
TIMEOUT_S = 60

pytestmark = pytest.mark.skipif(
    NODE is None,
    reason="node (Node.js) is not on PATH: the Flamenco job type is JavaScript and these tests run it with node",
)

BLEND = "/farm/shots/sh010.blend"
OUTPUT = "/farm/renders/sh010/######"

# What Flamenco accepts in a job type's settings (its AvailableJobSetting
# schema).
SETTING_TYPES = {"string": str, "int32": int, "float": (int, float), "bool": bool}
SETTING_SUBTYPES = {"file_path", "dir_path", "file_name", "hashed_file_path"}
SETTING_VISIBILITY = {"visible", "hidden", "submission", "web"}
SETTING_FIELDS = {
    "key",
    "type",
    "subtype",
    "choices",
    "propargs",
    "description",
    "default",
    "eval",
    "evalInfo",
    "visible",
    "required",
    "editable",
}


def _harness(action: str, job: dict | None = None, script: Path = SCRIPT) -> dict:
    # TZ fixes the {timestamp} expansion, which uses local time like Flamenco.
    env = dict(os.environ, TZ="UTC")
    proc = subprocess.run(
        [NODE, str(HARNESS), str(script), action],
        input=json.dumps(job) if job is not None else "",
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
        env=env,
        check=False,
    )
    assert proc.returncode == 0, f"harness failed ({proc.returncode}):\n{proc.stderr}"
    return json.loads(proc.stdout)


def compile_job(**settings) -> dict:
    base = {"frames": "1-10", "blendfile": BLEND, "render_output_path": OUTPUT}
    base.update(settings)
    # None removes a setting, as a job submitted without it.
    base = {key: value for key, value in base.items() if value is not None}
    return _harness("compile", {"name": "sh010", "created": "2024-01-02T03:04:05Z", "settings": base})


def compiled_tasks(**settings) -> list[dict]:
    result = compile_job(**settings)
    assert result["ok"], result.get("error")
    return result["tasks"]


def argv(command: dict) -> list[str]:
    """The command line a Flamenco Worker runs for a blender-render command:
    {exe} {exeArgs} {argsBefore} {blendfile} {args}, exeArgs left as its
    variable (the Manager expands it)."""
    assert command["name"] == "blender-render"
    p = command["parameters"]
    return [p["exe"], p["exeArgs"], *p["argsBefore"], *([p["blendfile"]] if p["blendfile"] else []), *p["args"]]


def option(args: list[str], flag: str) -> str:
    assert args.count(flag) == 1, f"{flag} given {args.count(flag)} times in {args}"
    return args[args.index(flag) + 1]


def frame_runs(task: dict) -> list[tuple[int, int]]:
    runs = []
    for command in task["commands"]:
        args = command["parameters"]["args"]
        runs.append((int(option(args, "-s")), int(option(args, "-e"))))
    return runs


# -- The script as a file ---------------------------------------------------------------------


def test_script_parses():
    proc = subprocess.run(
        [NODE, "--check", str(SCRIPT)], capture_output=True, text=True, timeout=TIMEOUT_S, check=False
    )
    assert proc.returncode == 0, proc.stderr


def test_harness_parses():
    proc = subprocess.run(
        [NODE, "--check", str(HARNESS)], capture_output=True, text=True, timeout=TIMEOUT_S, check=False
    )
    assert proc.returncode == 0, proc.stderr


# -- JOB_TYPE ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def job_type() -> dict:
    return _harness("job-type")


def test_job_type_has_a_label(job_type):
    assert isinstance(job_type["label"], str) and job_type["label"].strip()


def test_job_type_settings_have_the_fields_flamenco_requires(job_type):
    keys = [setting.get("key") for setting in job_type["settings"]]
    assert len(keys) == len(set(keys)), f"duplicate keys in {keys}"
    for setting in job_type["settings"]:
        where = f"setting {setting.get('key')!r}"
        assert isinstance(setting.get("key"), str) and setting["key"], where
        assert setting.get("type") in SETTING_TYPES, where
        assert set(setting) <= SETTING_FIELDS, f"{where}: unknown fields {set(setting) - SETTING_FIELDS}"
        if "subtype" in setting:
            assert setting["type"] == "string" and setting["subtype"] in SETTING_SUBTYPES, where
        if "visible" in setting:
            assert setting["visible"] in SETTING_VISIBILITY, where
        if "choices" in setting:
            assert setting["type"] == "string", f"{where}: choices need a string setting"
            assert setting["choices"] and all(isinstance(c, str) for c in setting["choices"]), where
        if "default" in setting:
            default = setting["default"]
            assert isinstance(default, SETTING_TYPES[setting["type"]]), where
            assert not (setting["type"] != "bool" and isinstance(default, bool)), where
            if "choices" in setting:
                assert default in setting["choices"], f"{where}: default {default!r} is not a choice"
        if "evalInfo" in setting:
            assert "eval" in setting, where
            assert set(setting["evalInfo"]) == {"showLinkButton", "description"}, where


def test_job_type_declares_the_settings_the_script_reads(job_type):
    settings = {setting["key"]: setting for setting in job_type["settings"]}
    for key in (
        "frames",
        "chunk_size",
        "mode",
        "over_engine",
        "preset",
        "render_output_root",
        "render_output_path",
        "blendfile",
        "format",
    ):
        assert key in settings, key
    for key in ("frames", "blendfile", "render_output_root", "mode"):
        assert settings[key].get("required") is True, key


def test_job_type_defaults_are_sensible(job_type):
    settings = {setting["key"]: setting for setting in job_type["settings"]}
    assert settings["chunk_size"]["default"] >= 1
    assert settings["chunk_size"]["propargs"]["min"] == 1
    assert settings["mode"]["default"] == "SOLIDWIRE"
    assert settings["mode"]["choices"] == ["SOLIDWIRE", "WIRE_OVER"]
    assert settings["over_engine"]["default"] == "SCENE"
    assert set(settings["over_engine"]["choices"]) == {"SCENE", "CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"}
    assert settings["preset"]["default"] == ""
    # The output path is computed from the root at submission and numbers frames with ######.
    assert "######" in settings["render_output_path"]["eval"]
    assert "settings.render_output_root" in settings["render_output_path"]["eval"]
    assert settings["render_output_path"].get("editable") is False


# -- Chunking ---------------------------------------------------------------------------------


def test_hundred_frames_in_chunks_of_ten():
    tasks = compiled_tasks(frames="1-100", chunk_size=10)
    assert [task["name"] for task in tasks] == [f"render-{s}-{s + 9}" for s in range(1, 101, 10)]
    for task, start in zip(tasks, range(1, 101, 10)):
        assert task["type"] == "blender"
        assert task["dependencies"] == []
        assert frame_runs(task) == [(start, start + 9)]


def test_last_chunk_is_shorter():
    tasks = compiled_tasks(frames="1-25", chunk_size=10)
    assert [task["name"] for task in tasks] == ["render-1-10", "render-11-20", "render-21-25"]
    assert frame_runs(tasks[-1]) == [(21, 25)]


def test_comma_list_chunks_by_frame_count():
    # Nine frames, three a task; the middle task spans the gap 6-7, so it
    # renders two runs rather than -s 4 -e 8 (which would add frames 6 and 7).
    tasks = compiled_tasks(frames="1-5,8,10-12", chunk_size=3)
    assert [task["name"] for task in tasks] == ["render-1-3", "render-4-5,8", "render-10-12"]
    assert [frame_runs(task) for task in tasks] == [[(1, 3)], [(4, 5), (8, 8)], [(10, 12)]]


def test_comma_list_in_one_chunk():
    tasks = compiled_tasks(frames="1-5,8,10-12", chunk_size=100)
    assert [task["name"] for task in tasks] == ["render-1-5,8,10-12"]
    assert frame_runs(tasks[0]) == [(1, 5), (8, 8), (10, 12)]


def test_comma_list_one_frame_a_task():
    tasks = compiled_tasks(frames="1-5,8,10-12", chunk_size=1)
    frames = [1, 2, 3, 4, 5, 8, 10, 11, 12]
    assert [task["name"] for task in tasks] == [f"render-{f}" for f in frames]
    assert [frame_runs(task) for task in tasks] == [[(f, f)] for f in frames]


def test_single_frame():
    tasks = compiled_tasks(frames="47", chunk_size=10)
    assert [task["name"] for task in tasks] == ["render-47"]
    assert frame_runs(tasks[0]) == [(47, 47)]


@pytest.mark.parametrize("frames", ["1..4,9", " 1 - 4 , 9 ", "9,1-4", "1-3,2-4,9,9"])
def test_frame_notations(frames):
    # Blender's "A..B", spaces, any order and overlaps all mean the same frames.
    tasks = compiled_tasks(frames=frames, chunk_size=10)
    assert [task["name"] for task in tasks] == ["render-1-4,9"]
    assert frame_runs(tasks[0]) == [(1, 4), (9, 9)]


@pytest.mark.parametrize("frames,chunk", [("1-100", 7), ("3,5-9,20-22,40", 2), ("0-0", 5), ("1-250", 32)])
def test_every_frame_rendered_once(frames, chunk):
    tasks = compiled_tasks(frames=frames, chunk_size=chunk)
    rendered = [f for task in tasks for start, end in frame_runs(task) for f in range(start, end + 1)]
    expected = set()
    for part in frames.split(","):
        first, _, last = part.partition("-")
        expected.update(range(int(first), int(last or first) + 1))
    assert rendered == sorted(expected)
    assert all(sum(e - s + 1 for s, e in frame_runs(task)) <= chunk for task in tasks)


def test_chunk_size_given_as_text():
    # Jobs submitted through the API may carry numbers as strings.
    assert len(compiled_tasks(frames="1-20", chunk_size="5")) == 4


# -- SOLIDWIRE mode: Blender's own render -------------------------------------------------------


def test_solidwire_command_line():
    tasks = compiled_tasks(frames="1-20", chunk_size=10, mode="SOLIDWIRE")
    command = tasks[1]["commands"][0]
    assert command["name"] == "blender-render"
    params = command["parameters"]
    assert params["exe"] == "{blender}"
    assert params["exeArgs"] == "{blenderArgs}"
    assert params["argsBefore"] == ["-b"]
    assert params["blendfile"] == BLEND
    # -j 1: every frame of the range, whatever frame step the scene was saved with.
    assert params["args"] == ["-E", "SOLIDWIRE", "-o", OUTPUT, "-s", "11", "-e", "20", "-j", "1", "-a"]
    assert argv(command) == [
        "{blender}",
        "{blenderArgs}",
        "-b",
        BLEND,
        "-E",
        "SOLIDWIRE",
        "-o",
        OUTPUT,
        "-s",
        "11",
        "-e",
        "20",
        "-j",
        "1",
        "-a",
    ]


def test_solidwire_is_the_default_mode():
    tasks = compiled_tasks(frames="1-30", mode=None, chunk_size=None)
    # chunk_size defaults to 10 as declared in JOB_TYPE.
    assert [task["name"] for task in tasks] == ["render-1-10", "render-11-20", "render-21-30"]
    assert "-E" in tasks[0]["commands"][0]["parameters"]["args"]


def test_blender_flags_come_before_render():
    # Blender applies arguments in order; -a renders with what came before it.
    for task in compiled_tasks(frames="1-5,8", chunk_size=10):
        for command in task["commands"]:
            args = argv(command)
            assert args[-1] == "-a"
            assert args.index(BLEND) < args.index("-E") < args.index("-a")
            for flag in ("-o", "-s", "-e", "-j"):
                assert args.index(BLEND) < args.index(flag) < args.index("-a")


def test_mode_is_case_insensitive():
    tasks = compiled_tasks(mode="wire_over", over_engine="cycles")
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "--over") == "CYCLES"


# -- WIRE_OVER mode and presets: the extension's command line -----------------------------------


def test_wire_over_command_line():
    tasks = compiled_tasks(frames="1-20", chunk_size=10, mode="WIRE_OVER", over_engine="CYCLES")
    command = tasks[1]["commands"][0]
    # The command line takes the image format from -o's extension; without a
    # format setting the job asks for PNG.
    assert argv(command) == [
        "{blender}",
        "{blenderArgs}",
        "-c",
        "solidwire",
        "render",
        BLEND,
        "-o",
        OUTPUT + ".png",
        "-s",
        "11",
        "-e",
        "20",
        "-j",
        "1",
        "-a",
        "--over",
        "CYCLES",
        "--progress",
        "json",
    ]


def test_wire_over_arguments_follow_the_command():
    # -c hands everything after the command name to the extension, so the file
    # and every option come after "-c solidwire render".
    tasks = compiled_tasks(frames="3-4", mode="WIRE_OVER", over_engine="BLENDER_EEVEE", preset="Blueprint")
    args = argv(tasks[0]["commands"][0])
    command_at = args.index("-c")
    assert args[command_at : command_at + 4] == ["-c", "solidwire", "render", BLEND]
    assert option(args, "-s") == "3" and option(args, "-e") == "4"
    assert option(args, "-j") == "1"
    assert option(args, "--over") == "BLENDER_EEVEE"
    assert option(args, "--preset") == "Blueprint"
    assert option(args, "--progress") == "json"
    assert "-E" not in args


@pytest.mark.parametrize("engine", ["SCENE", "CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"])
def test_wire_over_names_the_engine(engine):
    tasks = compiled_tasks(mode="WIRE_OVER", over_engine=engine)
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "--over") == engine


def test_wire_over_engine_defaults_to_the_scene():
    tasks = compiled_tasks(mode="WIRE_OVER", over_engine=None)
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "--over") == "SCENE"


def test_wire_over_gapped_chunk():
    tasks = compiled_tasks(frames="1-2,5", chunk_size=3, mode="WIRE_OVER", over_engine="CYCLES")
    assert len(tasks) == 1
    assert frame_runs(tasks[0]) == [(1, 2), (5, 5)]
    for command in tasks[0]["commands"]:
        assert command["parameters"]["argsBefore"] == ["-c", "solidwire", "render"]


def test_preset_uses_the_extension_command_line():
    tasks = compiled_tasks(frames="1-10", mode="SOLIDWIRE", preset="Technical Drawing")
    args = argv(tasks[0]["commands"][0])
    assert args[2:6] == ["-c", "solidwire", "render", BLEND]
    # One argument, spaces and all: no shell splits it.
    assert option(args, "--preset") == "Technical Drawing"
    # Plain SolidWire: no image underneath.
    assert "--over" not in args
    assert "-E" not in args


def test_preset_file():
    tasks = compiled_tasks(mode="WIRE_OVER", over_engine="CYCLES", preset="/farm/presets/ink.json")
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "--preset") == "/farm/presets/ink.json"


@pytest.mark.parametrize(
    "fmt,extension",
    [
        ("PNG", ".png"),
        ("JPEG", ".jpg"),
        ("TIFF", ".tif"),
        ("OPEN_EXR", ".exr"),
        ("OPEN_EXR_MULTILAYER", ".exr"),
        ("WEBP", ".webp"),
        ("BMP", ".bmp"),
        ("png", ".png"),
    ],
)
def test_command_line_output_gets_the_format_extension(fmt, extension):
    result = compile_job(mode="WIRE_OVER", over_engine="CYCLES", format=fmt)
    assert result["ok"], result.get("error")
    assert option(result["tasks"][0]["commands"][0]["parameters"]["args"], "-o") == OUTPUT + extension
    # The job records the path its frames really go to.
    assert result["settings"]["render_output_path"] == OUTPUT + extension


def test_preset_output_gets_the_format_extension():
    tasks = compiled_tasks(preset="Blueprint", format="OPEN_EXR")
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "-o") == OUTPUT + ".exr"


def test_output_extension_not_doubled():
    tasks = compiled_tasks(mode="WIRE_OVER", format="PNG", render_output_path="/farm/renders/sh010/f_####.PNG")
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "-o") == "/farm/renders/sh010/f_####.PNG"


def test_engine_output_left_to_blender():
    # Blender's -o adds the scene format's extension itself, any format.
    for fmt in ("PNG", "OPEN_EXR_MULTILAYER", "TARGA"):
        result = compile_job(mode="SOLIDWIRE", format=fmt)
        assert result["ok"], result.get("error")
        assert option(result["tasks"][0]["commands"][0]["parameters"]["args"], "-o") == OUTPUT
        assert result["settings"]["render_output_path"] == OUTPUT


def test_over_engine_ignored_in_solidwire_mode():
    tasks = compiled_tasks(mode="SOLIDWIRE", over_engine="CYCLES")
    assert "--over" not in argv(tasks[0]["commands"][0])


# -- Output path --------------------------------------------------------------------------------


def test_timestamp_in_output_path():
    result = compile_job(render_output_path="/farm/renders/sh010/{timestamp}/######")
    assert result["ok"], result.get("error")
    expanded = "/farm/renders/sh010/2024-01-02_030405/######"
    assert result["settings"]["render_output_path"] == expanded
    assert option(result["tasks"][0]["commands"][0]["parameters"]["args"], "-o") == expanded


def test_other_fields_in_output_path_are_left_alone():
    # {jobs} and friends are Flamenco variables, expanded later by the Manager.
    tasks = compiled_tasks(render_output_path="{render}/sh010/######")
    assert option(tasks[0]["commands"][0]["parameters"]["args"], "-o") == "{render}/sh010/######"


# -- Bad settings -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "settings,mentions",
    [
        ({"frames": ""}, "frames"),
        ({"frames": "   "}, "frames"),
        ({"frames": None}, "frames"),
        ({"frames": "10-1"}, "backwards"),
        ({"frames": "1-"}, "frames"),
        ({"frames": "a-b"}, "frames"),
        ({"frames": "1,,3"}, "frames"),
        ({"frames": "-5"}, "frames"),
        ({"frames": "1-3\n5"}, "frames"),
        ({"frames": "1-99999999999"}, "frames"),
        ({"chunk_size": 0}, "chunk_size"),
        ({"chunk_size": -3}, "chunk_size"),
        ({"chunk_size": 2.5}, "chunk_size"),
        ({"chunk_size": "ten"}, "chunk_size"),
        ({"mode": "CYCLES"}, "mode"),
        ({"mode": "WIREFRAME"}, "mode"),
        ({"mode": "WIRE_OVER", "over_engine": "LUXCORE"}, "over_engine"),
        ({"preset": "--thickness"}, "preset"),
        ({"preset": "a\nb"}, "preset"),
        ({"blendfile": ""}, "blendfile"),
        ({"blendfile": None}, "blendfile"),
        ({"render_output_path": ""}, "render_output_path"),
        ({"format": "FFMPEG"}, "FFMPEG"),
        ({"mode": "WIRE_OVER", "format": "TARGA"}, "format"),
        ({"preset": "Blueprint", "format": "HDR"}, "format"),
    ],
)
def test_bad_settings_are_refused(settings, mentions):
    result = compile_job(**settings)
    assert result["ok"] is False, f"{settings} compiled to {result.get('tasks')}"
    message = result["error"]
    assert message.strip() and "\n" not in message, repr(message)
    assert mentions in message, message
    # An Error object (with a message Flamenco can show), not a bare string.
    assert result["errorIsError"] is True


def test_image_formats_are_accepted():
    for fmt in ("PNG", "OPEN_EXR", "OPEN_EXR_MULTILAYER", "JPEG", "TARGA", "", None):
        assert compile_job(format=fmt)["ok"], fmt


# -- The stand-in follows Flamenco's job compiler ----------------------------------------------


def test_job_type_is_named_after_the_file(job_type):
    assert job_type["name"] == "solidwire"


def flamenco_chunks(frames: str, chunk_size: int) -> list[list[int]]:
    """Flamenco's own frameChunker (as the harness implements it), as frame lists."""
    chunks = _harness("frame-chunker", {"frames": frames, "chunk_size": chunk_size})
    result = []
    for chunk in chunks:
        numbers = []
        for part in chunk.split(","):
            first, _, last = part.partition("-")
            numbers.extend(range(int(first), int(last or first) + 1))
        result.append(numbers)
    return result


@pytest.mark.parametrize("frames, chunk", [("1-100", 10), ("1..10,20-25,40", 4), ("5,3,4,4", 2), ("7", 3)])
def test_tasks_hold_the_frames_flamencos_chunker_gives(frames, chunk):
    """The script chunks frames itself (it needs runs for -s/-e); each task
    renders exactly the frames of the chunk Flamenco's frameChunker makes."""
    tasks = compiled_tasks(frames=frames, chunk_size=chunk)
    ours = [[f for start, end in frame_runs(task) for f in range(start, end + 1)] for task in tasks]
    assert ours == flamenco_chunks(frames, chunk)


@pytest.mark.parametrize(
    "body, works",
    [
        ("formatTimestampLocal(job.created)", True),
        ("job.created.getFullYear()", False),  # a Go time.Time, not a Date
        ("job.jobType + job.name + job.status", True),
        ("path.join('a', path.basename('/x/y.blend'))", True),
        ("frameChunker('1-4', 2).length", True),
        ("require('fs')", False),
        ("console.log('x')", False),
        ("undeclared = 1", False),  # strict mode
    ],
)
def test_the_stand_in_offers_what_the_manager_offers(tmp_path, body, works):
    script = tmp_path / "probe.js"
    script.write_text(
        f"const JOB_TYPE = {{label: 'Probe', settings: []}};\nfunction compileJob(job) {{ {body}; }}\n",
        encoding="utf-8",
    )
    result = _harness("compile", {"name": "probe", "settings": {}}, script=script)
    assert result["ok"] is works, result
