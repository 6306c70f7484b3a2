"""The add-on's method menu offers only methods the snell module knows, each drawn by name."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))  # Blender runs the script without its folder on the path
from blender_support import check, enable_addon  # noqa: E402

enable_addon()
from snell_blender import properties, runtime  # noqa: E402

check(runtime.problem() is None, f"the add-on found the module ({runtime.status()})")
import snell  # noqa: E402  (put on the path by the add-on's runtime)

known = {name for name, _ in snell.methods()}
offered = [name for name, _, _ in properties.METHODS]
check(set(offered) <= known, f"every menu entry is a method of snell.methods(): {offered} within {sorted(known)}")
check("trace" in offered and "none" in offered, "the menu has the reference and the plain view")
