"""`pip install .[usd]` gives what a user expects: `import snell` from site-packages and the snell-usd command.

Run by ctest with the venv's python (scripts/bootstrap test installs the
package into build/venv/pip from a clean copy of the tree), without
PYTHONPATH and from outside the source tree, so nothing of the build tree
can stand in for the installed package.
"""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np

import snell

BIN = Path(sys.executable).parent


def test_snell_imports_from_the_venvs_site_packages():
    site = Path(sysconfig.get_paths()["platlib"])
    assert Path(snell.__file__).resolve().is_relative_to(site.resolve()), snell.__file__
    assert "PYTHONPATH" not in os.environ or not os.environ["PYTHONPATH"]
    assert snell.version() == snell.__version__ == "0.1.0"


def test_the_installed_module_renders_on_the_device():
    positions = np.float32([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    quad = snell.Mesh(positions, np.float32([[0, 0, 1]] * 4), np.uint32([[0, 1, 2], [0, 2, 3]]), material=0)
    with snell.Device(validation=os.environ.get("SNELL_VALIDATION") == "1") as device:
        scene = snell.Scene.from_arrays([quad], materials=[snell.Material(base_color=(0.2, 0.6, 0.9, 1))])
        with snell.Renderer(device, scene) as renderer:
            rgba = renderer.render(snell.View(32, 24, eye=(0, 0, 3), method="trace"))
        assert device.validation_messages == 0
    centre, corner = rgba[12, 16, :3], rgba[0, 0, :3]
    assert centre[2] > centre[0] and not np.allclose(centre, corner), (centre, corner)


def test_snell_usd_is_a_console_script_of_the_package(tmp_path):
    script = BIN / "snell-usd"
    assert script.exists(), f"{script} is missing: the package's [project.scripts] did not install it"
    done = subprocess.run([str(script), "--help"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "render" in done.stdout and "info" in done.stdout, done.stderr


def test_snell_usd_renders_a_stage_usd_core_wrote(tmp_path):
    from pxr import Usd
    from usd_card import define_card

    stage_path = tmp_path / "card.usda"
    stage = Usd.Stage.CreateNew(str(stage_path))
    define_card(stage)
    stage.GetRootLayer().Save()
    out = tmp_path / "card.png"
    done = subprocess.run([str(BIN / "snell-usd"), "--quiet", "render", str(stage_path), "-o", str(out),
                           "--size", "48x32"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert out.exists() and out.stat().st_size > 100
