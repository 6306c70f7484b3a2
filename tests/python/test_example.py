"""docs/python.md's complete example is examples/python/lens.py, and it runs."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "python" / "lens.py"


def test_the_documented_example_is_the_example_file():
    documented = (ROOT / "docs" / "python.md").read_text().split("```python\n", 1)[1].split("```", 1)[0]
    assert documented in EXAMPLE.read_text()
    assert len(EXAMPLE.read_text().splitlines()) < 40


def test_the_example_writes_its_four_frames(tmp_path):
    done = subprocess.run([sys.executable, str(EXAMPLE)], cwd=tmp_path, capture_output=True, text=True, timeout=300,
                          env=dict(os.environ))
    assert done.returncode == 0, done.stderr
    frames = [tmp_path / f"lens_{i}.ppm" for i in range(4)]
    assert all(f.stat().st_size == len(b"P6 320 240 255\n") + 320 * 240 * 3 for f in frames)
    assert frames[0].read_bytes() != frames[3].read_bytes(), "the squash changed nothing"
