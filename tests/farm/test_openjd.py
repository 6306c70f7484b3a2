"""`snell farm openjd`: an Open Job Description template (jobtemplate-2023-09
with TASK_CHUNKING), held against the fields the specification documents
(its wiki's Template Schemas page and the TASK_CHUNKING RFC; it publishes no
JSON Schema to test against). No OpenJD runner is packaged for Debian, so
the template's task command lines are expanded here as the specification
says a worker expands them, and run.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path
from typing import Any

import yaml

SNELL = os.environ["SNELL_BINARY"]
IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")
FORMAT_REFERENCE = re.compile(r"\{\{\s*([A-Za-z_.]+)\s*\}\}")


def snell(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([SNELL, *args], cwd=cwd, capture_output=True, text=True, timeout=120)


def write_template(folder: Path, *extra: str, name: str = "job.yaml") -> dict[str, Any]:
    assert snell("eye", "-o", "eye.glb", "--resolution", "16", cwd=folder).returncode == 0
    result = snell("farm", "openjd", "eye.glb", "--images", "frames/eye.####.png", "--frames", "1-10", "--chunk", "4",
                   "--size", "32x24", *extra, "-o", name, cwd=folder)
    assert result.returncode == 0, result.stderr
    text = (folder / name).read_text()
    return yaml.safe_load(text) if name.endswith(".yaml") else json.loads(text)


def parameter(template: dict[str, Any], name: str) -> dict[str, Any]:
    return next(p for p in template["parameterDefinitions"] if p["name"] == name)


def on_run(template: dict[str, Any]) -> dict[str, Any]:
    return template["steps"][0]["script"]["actions"]["onRun"]


def test_the_template_has_the_documented_top_level_fields(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    assert set(t) <= {"specificationVersion", "extensions", "name", "description", "parameterDefinitions",
                      "jobEnvironments", "steps", "$schema"}
    assert t["specificationVersion"] == "jobtemplate-2023-09"
    assert t["extensions"] == ["TASK_CHUNKING"]
    assert 1 <= len(t["name"]) <= 128 and len(t["description"]) <= 2048
    assert 1 <= len(t["parameterDefinitions"]) <= 50
    for p in t["parameterDefinitions"]:
        assert IDENTIFIER.match(p["name"]), p["name"]
        assert p["type"] in {"STRING", "PATH", "INT", "FLOAT"}
    assert [s["name"] for s in t["steps"]] == ["Render"]


def test_the_scene_and_image_folder_are_path_parameters_that_a_farm_maps(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    scene, images = parameter(t, "SceneFile"), parameter(t, "OutputDirectory")
    assert (scene["type"], scene["objectType"], scene["dataFlow"]) == ("PATH", "FILE", "IN")
    assert (images["type"], images["objectType"], images["dataFlow"]) == ("PATH", "DIRECTORY", "OUT")
    assert scene["default"] == str(tmp_path / "eye.glb")
    assert images["default"] == str(tmp_path / "frames")
    assert parameter(t, "OutputName")["default"] == "eye.####.png"


def test_the_frames_are_a_chunked_task_parameter_over_the_frame_range(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    assert parameter(t, "Frames") == {**parameter(t, "Frames"), "type": "STRING", "default": "1-10"}
    assert parameter(t, "ChunkSize")["default"] == 4 and parameter(t, "ChunkSize")["minValue"] == 1
    (task,) = t["steps"][0]["parameterSpace"]["taskParameterDefinitions"]
    assert task["name"] == "Frame" and task["type"] == "CHUNK[INT]"
    assert task["range"] == "{{Param.Frames}}"
    assert task["chunks"] == {"defaultTaskCount": "{{Param.ChunkSize}}", "rangeConstraint": "NONCONTIGUOUS"}


def test_a_stepped_list_is_written_in_open_job_descriptions_range_syntax(tmp_path: Path) -> None:
    assert snell("eye", "-o", "eye.glb", "--resolution", "16", cwd=tmp_path).returncode == 0
    result = snell("farm", "openjd", "eye.glb", "--images", "f.#.png", "--frames", "1-9x2,20", "-o", "job.yaml",
                   cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert parameter(yaml.safe_load((tmp_path / "job.yaml").read_text()), "Frames")["default"] == "1-9:2,20"


def test_each_task_runs_snell_render_on_its_chunk_and_asks_for_a_gpu(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    run = on_run(t)
    assert run["command"] == "snell"
    args = run["args"]
    assert args[:2] == ["render", "{{Param.SceneFile}}"]
    assert args[args.index("--frames") + 1] == "{{Task.Param.Frame}}"
    assert "--skip-existing" in args and args[args.index("--size") + 1] == "32x24"
    assert args[args.index("--method") + 1] == "trace", "auto could choose differently in each task"
    assert run["cancelation"]["mode"] == "NOTIFY_THEN_TERMINATE"
    assert 1 <= run["cancelation"]["notifyPeriodInSeconds"] <= 600
    assert t["steps"][0]["hostRequirements"]["amounts"] == [{"name": "amount.worker.gpu", "min": 1}]


def test_every_format_string_names_a_defined_parameter(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    job = {f"Param.{p['name']}" for p in t["parameterDefinitions"]}
    task = {"Task.Param.Frame"}
    step = t["steps"][0]
    args = on_run(t)["args"] + step["stepEnvironments"][0]["script"]["actions"]["onEnter"]["args"]
    for arg in args:
        for reference in FORMAT_REFERENCE.findall(arg):
            assert reference in job | task, reference


def test_without_gpus_any_worker_may_run_it(tmp_path: Path) -> None:
    t = write_template(tmp_path, "--gpus-per-task", "0")
    assert "hostRequirements" not in t["steps"][0]


def test_the_json_form_holds_the_same_template(tmp_path: Path) -> None:
    assert write_template(tmp_path, name="job.json") == write_template(tmp_path, name="job.yaml")


def expand_chunks(frames: list[int], count: int) -> list[str]:
    """NONCONTIGUOUS chunks as the specification's conformance tests write them: 1-4, 5-8, then 9,10."""
    chunks = []
    for start in range(0, len(frames), count):
        part = frames[start:start + count]
        contiguous = part == list(range(part[0], part[-1] + 1))
        chunks.append(f"{part[0]}-{part[-1]}" if contiguous and len(part) > 2 else ",".join(map(str, part)))
    return chunks


def test_its_tasks_command_lines_render_the_shot_as_a_worker_would_run_them(tmp_path: Path) -> None:
    t = write_template(tmp_path)
    values = {f"Param.{p['name']}": str(p["default"]) for p in t["parameterDefinitions"]}
    chunks = expand_chunks(list(range(1, 11)), int(values["Param.ChunkSize"]))
    assert chunks == ["1-4", "5-8", "9,10"]
    (environment,) = t["steps"][0]["stepEnvironments"]
    enter = environment["script"]["actions"]["onEnter"]
    args = [FORMAT_REFERENCE.sub(lambda m: values[m.group(1)], a) for a in enter["args"]]
    assert subprocess.run([enter["command"], *args], cwd=tmp_path, timeout=30).returncode == 0
    for chunk in chunks:
        values["Task.Param.Frame"] = chunk
        args = [FORMAT_REFERENCE.sub(lambda m: values[m.group(1)], a) for a in on_run(t)["args"]]
        result = subprocess.run([SNELL, *args], cwd=tmp_path, capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, f"{args}\n{result.stderr}"
    assert sorted(p.name for p in (tmp_path / "frames").glob("eye.*.png")) == [f"eye.{f:04d}.png" for f in range(1, 11)]


def test_a_template_name_that_is_neither_yaml_nor_json_is_a_usage_error(tmp_path: Path) -> None:
    assert snell("eye", "-o", "eye.glb", "--resolution", "16", cwd=tmp_path).returncode == 0
    result = snell("farm", "openjd", "eye.glb", "--images", "f.#.png", "--frames", "1-2", "-o", "job.txt", cwd=tmp_path)
    assert result.returncode == 2 and "a template ends in .yaml, .yml or .json" in result.stderr, result.stderr
