"""Runs one of the add-on's test scripts in `bpy`, Blender as a Python module (PyPI's wheels).

    python run_in_bpy.py test_f12_matches_gltf_export.py [ARGUMENTS...]

The scripts are the ones Debian's Blender runs with --python; here they run
in the module after a factory reset, and their first exception fails the
test (exit 1). The process leaves with os._exit: bpy 4.5's module, exiting
normally, waits forever on a thread of its own (a condition variable its
exit handler destroys while the thread still waits on it).
"""

from __future__ import annotations

import os
import runpy
import sys
import traceback


def main(script: str, arguments: list) -> int:
    import bpy

    print(f"bpy {bpy.app.version_string}, Python {sys.version.split()[0]}: {os.path.basename(script)}", flush=True)
    bpy.ops.wm.read_factory_settings(use_empty=False)
    sys.argv = [script, "--", *arguments]  # as Blender's own command line hands a script its arguments
    try:
        runpy.run_path(script, run_name="__main__")
    except SystemExit as leaving:
        return int(leaving.code or 0)
    except BaseException:
        traceback.print_exc()
        return 1
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        print(__doc__, file=sys.stderr)
        code = 2
    else:
        code = main(sys.argv[1], sys.argv[2:])
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
