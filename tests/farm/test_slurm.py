"""`snell farm slurm` on a real one-node Slurm cluster (slurm_cluster.py).

The README's "On a farm" block is run as written: a 6-frame lavapipe render
of the procedural eye in 3 array tasks, then a lost frame rendered again.
Each frame's pixels are held against `snell render` of that frame alone; a
failing task must fail the job with a summary naming its frame; bad input is
refused before anything reaches Slurm. Every wait has a deadline.
"""

from __future__ import annotations

import json
import os
import subprocess
import zlib
from pathlib import Path
from typing import Iterator

import pytest

from slurm_cluster import SlurmCluster, missing_programs, slurm_cluster

SNELL = os.environ["SNELL_BINARY"]
README = Path(__file__).resolve().parents[2] / "README.md"
MARKER = "<!-- tests/farm/test_slurm.py runs the commands of this block -->"
DEADLINE_S = 180  # for any one command, --wait included

def readme_commands() -> list[str]:
    """The command lines of the README block the marker points at."""
    after = README.read_text().split(MARKER, 1)[1]
    block = after.split("```sh\n", 1)[1].split("```", 1)[0]
    return [line for line in block.splitlines() if line.strip()]


def run(command: str, cwd: Path, cluster: SlurmCluster, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """A shell command line as a user types it, with this build's snell first on PATH."""
    environment = dict(cluster.env)
    environment["PATH"] = f"{Path(SNELL).parent}:{environment.get('PATH', '')}"
    environment.update(env or {})
    return subprocess.run(["bash", "-c", command], cwd=cwd, env=environment, capture_output=True, text=True,
                          timeout=DEADLINE_S)


def pixels(png: Path) -> bytes:
    """A PNG's scanlines, inflated: what is left when the file's metadata is set aside."""
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", png
    idat, at = b"", 8
    while at < len(data):
        length = int.from_bytes(data[at:at + 4], "big")
        kind = data[at + 4:at + 8]
        if kind == b"IDAT":
            idat += data[at + 8:at + 8 + length]
        at += 12 + length
    return zlib.decompress(idat)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[SlurmCluster]:
    missing = missing_programs()
    assert not missing, f"the farm tests need {missing} (Debian 12: slurmctld slurmd slurm-client munge)"
    with slurm_cluster(tmp_path_factory.mktemp("slurm")) as running:
        yield running


@pytest.fixture(scope="module")
def shot(cluster: SlurmCluster, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The README's first two commands, run where a user would run them."""
    folder = tmp_path_factory.mktemp("shot")
    for command in readme_commands()[:2]:
        result = run(command, folder, cluster)
        assert result.returncode == 0, f"{command}\n{result.stdout}\n{result.stderr}\n{cluster.logs()}"
    return folder


def test_the_readme_submission_writes_every_frame_and_a_summary(shot: Path) -> None:
    frames = sorted(p.name for p in (shot / "frames").glob("eye.*.png"))
    assert frames == [f"eye.{f:04d}.png" for f in range(1, 7)]
    summary = json.loads((shot / "frames/.snell-farm/eye/summary.json").read_text())
    assert summary["ok"] and summary["frames_written"] == 6 and summary["missing"] == []
    assert [t["frames"] for t in summary["tasks"]] == ["1,2", "3,4", "5,6"]
    assert all(t["exit_code"] == 0 for t in summary["tasks"])


def test_each_frame_has_the_pixels_of_a_render_of_that_frame_alone(shot: Path, cluster: SlurmCluster) -> None:
    seen = set()
    for frame in range(1, 7):
        alone = shot / f"alone.{frame}.png"
        result = run(f"snell render eye.glb -o {alone.name} --frames {frame} --fps 2 --size 64x48 --method trace -q",
                     shot, cluster)
        assert result.returncode == 0, result.stderr
        farmed = pixels(shot / f"frames/eye.{frame:04d}.png")
        assert farmed == pixels(alone), f"frame {frame} differs from its render alone"
        seen.add(farmed)
    assert len(seen) >= 4, "the eye should move between the frames, or the test proves little"


def test_the_readme_resubmission_renders_only_the_lost_frame(shot: Path, cluster: SlurmCluster) -> None:
    frames = shot / "frames"
    before = {p.name: p.stat().st_mtime_ns for p in frames.glob("eye.*.png")}
    logs_before = set((frames / ".snell-farm/eye/logs").iterdir())
    for command in readme_commands()[2:]:
        result = run(command, shot, cluster)
        assert result.returncode == 0, f"{command}\n{result.stdout}\n{result.stderr}"
    assert "1 task(s)" in result.stdout and "1 of 6 frames missing" in result.stdout, result.stdout
    after = {p.name: p.stat().st_mtime_ns for p in frames.glob("eye.*.png")}
    assert set(after) == set(before)
    changed = [name for name in after if after[name] != before[name]]
    assert changed == ["eye.0004.png"], changed
    task_logs = [p.name for p in set((frames / ".snell-farm/eye/logs").iterdir()) - logs_before if "check" not in p.name]
    assert len(task_logs) == 1 and task_logs[0].endswith("_1.out"), task_logs


def test_a_failing_task_fails_the_job_and_the_summary_names_its_frame(cluster: SlurmCluster, tmp_path: Path) -> None:
    assert run("snell eye -o eye.glb --resolution 16", tmp_path, cluster).returncode == 0
    (tmp_path / "out/f.2.png").mkdir(parents=True)  # frame 2 cannot be written: a folder holds its name
    result = run("snell farm slurm eye.glb -o 'out/f.#.png' --frames 1-2 --chunk 1 --size 32x24 --wait", tmp_path, cluster)
    assert result.returncode == 1, f"{result.stdout}\n{result.stderr}"
    assert "missing frames 2" in result.stderr and "task 1 (frames 2) exited 1" in result.stderr, result.stderr
    summary = json.loads((tmp_path / "out/.snell-farm/f/summary.json").read_text())
    assert summary["ok"] is False and summary["missing"] == [2]
    assert [t["exit_code"] for t in summary["tasks"]] == [0, 1]
    log = Path(summary["tasks"][1]["log"]).read_text()
    assert "f.2.png: is a folder" in log, log


def test_a_partition_that_does_not_exist_is_refused_naming_those_that_do(cluster: SlurmCluster, tmp_path: Path) -> None:
    assert run("snell eye -o eye.glb --resolution 16", tmp_path, cluster).returncode == 0
    result = run("snell farm slurm eye.glb -o 'f.#.png' --frames 1-2 --partition gpu-a100", tmp_path, cluster)
    assert result.returncode == 2, result.stderr
    assert "--partition gpu-a100: the cluster has no such partition; it has debug" in result.stderr, result.stderr
    assert not (tmp_path / ".snell-farm").exists()


def test_a_scene_that_does_not_load_is_refused_before_submitting(cluster: SlurmCluster, tmp_path: Path) -> None:
    (tmp_path / "broken.glb").write_bytes(b"glTF\x02\x00\x00\x00truncated")
    result = run("snell farm slurm broken.glb -o 'f.#.png' --frames 1-2", tmp_path, cluster)
    assert result.returncode == 1, result.stderr
    assert "broken.glb" in result.stderr, result.stderr
    assert not (tmp_path / ".snell-farm").exists()


def test_without_sbatch_the_error_says_so(cluster: SlurmCluster, tmp_path: Path) -> None:
    assert run("snell eye -o eye.glb --resolution 16", tmp_path, cluster).returncode == 0
    result = run(f"PATH=/nonexistent {SNELL} farm slurm eye.glb -o 'f.#.png' --frames 1-2", tmp_path, cluster)
    assert result.returncode == 1, result.stderr
    assert "sbatch is not on PATH" in result.stderr, result.stderr


def test_a_dry_run_prints_the_batch_script_and_submits_nothing(cluster: SlurmCluster, tmp_path: Path) -> None:
    assert run("snell eye -o eye.glb --resolution 16", tmp_path, cluster).returncode == 0
    result = run("snell farm slurm eye.glb -o 'f.####.png' --frames 1001-1005 --chunk 2 --time 10 --dry-run",
                 tmp_path, cluster)
    assert result.returncode == 0, result.stderr
    script = result.stdout
    assert script.startswith("#!/bin/bash") and "#SBATCH --time=10" in script
    assert "tasks=(\n  1001,1002\n  1003,1004\n  1005\n)" in script, script
    assert "--skip-existing" in script and "--method trace" in script
    assert "would submit: sbatch --array=0-2" in script
    assert not (tmp_path / ".snell-farm").exists()
