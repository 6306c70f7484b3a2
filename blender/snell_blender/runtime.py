# SPDX-License-Identifier: GPL-3.0-or-later
"""What the add-on needs at run time, found once: numpy, the snell module, a Vulkan device.

Nothing here raises into Blender: a missing piece becomes a sentence the
panels, the viewport and the console show, and the engine draws nothing.
"""

from __future__ import annotations

import importlib
import sys
from typing import Optional

# Where the add-on cannot map Blender's data exactly, the panel and overlay say so.
AREA_LIGHT_NOTE = "area lights shine as point lights of the same power"

_device = None
_problem: Optional[str] = None
_tried = False
# What the last scene snell built holds that it cannot draw (materials' nodes), for the panel.
_scene_problems: list = []


def _preferences():
    import bpy

    addon = bpy.context.preferences.addons.get(__package__)
    return addon.preferences if addon is not None else None


def _import_snell():
    """The snell module, from the preferences' folder first when one is set."""
    prefs = _preferences()
    folder = prefs.module_path if prefs is not None else ""
    if folder:
        import os

        folder = os.path.abspath(bpy_path(folder))
        if folder not in sys.path:
            sys.path.insert(0, folder)
    return importlib.import_module("snell")


def bpy_path(path: str) -> str:
    import bpy

    return bpy.path.abspath(path)


def device():
    """The shared snell.Device, made on first use; None (and problem() says why) when it cannot be."""
    global _device, _problem, _tried
    if _device is not None or _tried:
        return _device
    _tried = True
    try:
        import numpy  # noqa: F401  (snell's arrays are numpy's)
    except ImportError:
        _problem = "snell needs numpy in Blender's Python (Debian: apt install python3-numpy)"
    else:
        try:
            snell = _import_snell()
        except ImportError as error:
            _problem = (f"the snell Python module is not found ({error}); install the extension that "
                        "scripts/blender_extension builds (its wheels hold the module), or `cmake --install`, "
                        "or set its folder in the add-on's preferences")
        else:
            prefs = _preferences()
            name = prefs.device if prefs is not None else ""
            try:
                # Interop lets the viewport hand snell's image to OpenGL without a copy.
                _device = snell.Device(device=name, interop=True)
            except snell.Error:
                try:
                    _device = snell.Device(device=name)
                except snell.Error as error:
                    _problem = f"snell found no Vulkan device it can use: {error}"
    if _problem:
        print(f"snell: {_problem}", file=sys.stderr)
    return _device


def note_scene_problems(problems: list) -> None:
    """Keeps what the last scene built could not map, for the panel (the console has it already)."""
    global _scene_problems
    _scene_problems = list(problems)


def scene_problems() -> list:
    """What the last scene snell built holds that it cannot draw, one sentence each."""
    return list(_scene_problems)


def problem() -> Optional[str]:
    """Why the engine cannot draw, or None."""
    device()
    return _problem


def status() -> str:
    """One line for the panels: the device, or the problem."""
    d = device()
    if d is None:
        return _problem or "snell is not loaded"
    import snell

    return f"snell {snell.version()} on {d.name}"


def retry() -> None:
    """Forgets a failed start, so the next use tries again (after the preferences change)."""
    global _device, _problem, _tried
    _device, _problem, _tried = None, None, False


def release() -> None:
    """Lets go of the device (on unregister)."""
    global _device
    if _device is not None:
        _device.close()
    _device = None
    retry()
