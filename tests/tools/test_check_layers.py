"""check_layers.py holds each layer rule: one small tree per rule, in tmp_path.

A clean tree that keeps to every rule in the ways the real one does (lazy
imports, relative ones, a pass's subfolder) must pass; each other tree breaks
one rule once, and its message must name the file, what it imports or
includes, and the rule.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # check_layers.py, beside this file

import check_layers  # noqa: E402

SCRIPT = Path(__file__).resolve().parent / "check_layers.py"

# The ways the real tree keeps to the rules: each file, what it holds.
CLEAN = {
    "include/snell/snell.h": '#include "snell/defaults.h"\n',
    "src/vk/context.h": '#include "shared/trace.h"\n',
    "src/render/renderer.cpp": '#include "render/renderer.h"\n#include "vk/context.h"\n',
    "python/snell_module.cpp": "#include <snell/snell.h>\n",
    "python/snell/__init__.py": "from ._snell import Device, View\n",
    "python/snell/usd/__init__.py": "from .. import Device\nfrom ._reader import read\n",
    "python/snell/usd/_reader.py": "import numpy as np\n\n\ndef read():\n    from .. import Error\n",
    "blender/snell_blender/__init__.py": "from . import engine, runtime\n",
    "blender/snell_blender/engine.py": ("import bpy\n\nfrom . import runtime\n\n\ndef render():\n"
                                        "    import snell\n    from snell import View\n"
                                        "    from snell.usd import Stage\n    from .sync import SceneSync\n"),
    "blender/snell_blender/runtime.py": ("import importlib\n\n\ndef module():\n"
                                         '    return importlib.import_module("snell")\n'),
    "blender/snell_blender/sync.py": "from . import runtime\n",
    "shaders/shared/scene.h": '#include "shared_types.h"\n#include <cstdint>\n',
    "shaders/shared/shared_types.h": "",
    "shaders/common/scene.glsl": '#include "../shared/scene.h"\n',
    "shaders/common/path.glsl": '#include "scene.glsl"\n',
    "shaders/comp/bvh/bvh_node.glsl": '#include "../../shared/scene.h"\n',
    "shaders/comp/trace.comp": '#include "../shared/scene.h"\n#include "bvh/bvh_node.glsl"\n'
                               '#include "../common/path.glsl"\n',
    "shaders/raster/raster_vertex.vert": '#include "../common/scene.glsl"\n',
}


def tree(root: Path, files: dict[str, str]) -> Path:
    """A source tree at `root` holding `files` (path: text)."""
    for relative, text in files.items():
        path = root / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return root


def the_violation(root: Path, files: dict[str, str]) -> str:
    """The one message check_layers gives a tree of `files`, which breaks one rule once."""
    found = check_layers.violations(tree(root, files))
    assert len(found) == 1, found
    return found[0]


def test_a_clean_tree_has_no_violations(tmp_path: Path) -> None:
    assert check_layers.violations(tree(tmp_path, CLEAN)) == []


def test_a_cpp_include_of_a_layer_above_is_reported(tmp_path: Path) -> None:
    message = the_violation(tmp_path, {"src/vk/buffer.h": '#include "render/bvh.h"\n'})
    assert "src/vk/buffer.h" in message and "render/bvh.h" in message
    assert "the vk layer may not include the render layer above it" in message


def test_a_usd_module_importing_bpy_lazily_is_reported(tmp_path: Path) -> None:
    files = {"python/snell/usd/_stage.py": "def frame():\n    import bpy\n"}
    message = the_violation(tmp_path, files)
    assert message.startswith("python/snell/usd/_stage.py:2: imports bpy (import bpy)")
    assert "snell.usd (python/snell/usd/) may not import Blender or the add-on" in message


def test_a_usd_module_importing_the_add_on_is_reported(tmp_path: Path) -> None:
    files = {"python/snell/usd/_stage.py": "from snell_blender.camera import to_snell\n",
             "blender/snell_blender/__init__.py": "",
             "blender/snell_blender/camera.py": ""}
    message = the_violation(tmp_path, files)
    assert "python/snell/usd/_stage.py:1: imports snell_blender.camera.to_snell" in message
    assert "may not import Blender or the add-on (snell_blender)" in message


def test_the_core_package_importing_snell_usd_is_reported(tmp_path: Path) -> None:
    files = {"python/snell/__init__.py": "from .usd import Stage\n", "python/snell/usd/__init__.py": ""}
    message = the_violation(tmp_path, files)
    assert "python/snell/__init__.py:1: imports snell.usd.Stage (from .usd import Stage)" in message
    assert "the core snell package may not import snell.usd, the layer above it" in message


def test_the_add_on_importing_snell_private_module_is_reported(tmp_path: Path) -> None:
    files = {"blender/snell_blender/__init__.py": "", "blender/snell_blender/sync.py": "import snell._snell\n"}
    message = the_violation(tmp_path, files)
    assert "blender/snell_blender/sync.py:1: imports snell._snell (import snell._snell)" in message
    assert "the add-on imports snell only through its public modules" in message
    assert "not the private _snell" in message


def test_the_add_on_importing_a_private_module_of_snell_usd_is_reported(tmp_path: Path) -> None:
    files = {"blender/snell_blender/__init__.py": "",
             "blender/snell_blender/shot.py": "def feed():\n    from snell.usd._reader import read\n"}
    message = the_violation(tmp_path, files)
    assert "blender/snell_blender/shot.py:2: imports snell.usd._reader.read" in message
    assert "not the private _reader" in message


def test_an_add_on_import_cycle_is_reported(tmp_path: Path) -> None:
    files = {"blender/snell_blender/__init__.py": "from . import engine\n",
             "blender/snell_blender/engine.py": "from . import sync\n",
             "blender/snell_blender/sync.py": "def scene():\n    from .engine import settings\n"}
    message = the_violation(tmp_path, files)
    assert "import cycle engine -> sync -> engine" in message
    assert "blender/snell_blender/engine.py:1 from . import sync" in message
    assert "blender/snell_blender/sync.py:2 from .engine import settings" in message
    assert "the add-on's modules may not import one another in a cycle" in message


def test_a_shared_shader_including_common_is_reported(tmp_path: Path) -> None:
    files = {"shaders/shared/trace.h": '#include "../common/optics.glsl"\n', "shaders/common/optics.glsl": ""}
    message = the_violation(tmp_path, files)
    assert message.startswith('shaders/shared/trace.h:1: includes "../common/optics.glsl" '
                               "(shaders/common/optics.glsl)")
    assert "shaders/shared/ may include only shaders/shared/" in message


def test_a_pass_shader_including_another_pass_folder_is_reported(tmp_path: Path) -> None:
    files = {"shaders/raster/raster_fragment.frag": '#include "../comp/bvh/bvh_node.glsl"\n'}
    message = the_violation(tmp_path, files)
    assert 'shaders/raster/raster_fragment.frag:1: includes "../comp/bvh/bvh_node.glsl"' in message
    assert "shaders/raster/ may include only itself, its subfolders, shaders/common/ and shaders/shared/" in message


def test_a_pass_subfolder_including_its_parent_is_reported(tmp_path: Path) -> None:
    files = {"shaders/comp/bvh/bvh_refit.comp": '#include "../trace_common.glsl"\n'}
    message = the_violation(tmp_path, files)
    assert "shaders/comp/bvh/bvh_refit.comp:1" in message and "(shaders/comp/trace_common.glsl)" in message


def test_the_script_exits_1_and_prints_each_violation(tmp_path: Path) -> None:
    files = dict(CLEAN, **{"src/vk/buffer.h": '#include "render/bvh.h"\n'})
    run = subprocess.run([sys.executable, str(SCRIPT), str(tree(tmp_path, files))], capture_output=True, text=True)
    assert run.returncode == 1
    assert "src/vk/buffer.h: includes render/bvh.h" in run.stdout


def test_the_script_exits_0_on_a_clean_tree(tmp_path: Path) -> None:
    run = subprocess.run([sys.executable, str(SCRIPT), str(tree(tmp_path, CLEAN))], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout
