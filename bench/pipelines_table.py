#!/usr/bin/env python3
"""Side by side, each build's trace registers: the GPU's driver and AMD's compiler.

Reads FOLDER/pipelines-NAME-gpu.json and FOLDER/pipelines-NAME-gfx1100.json
(`snell bench pipelines --json`, as bench/compare.sh ROWS=pipelines writes
them) for each NAME given, and prints one Markdown row per trace
specialisation: the GPU's registers and, on gfx1100, VGPRs + spilled VGPRs.
"""
import json
import sys
from pathlib import Path


def registers(path: Path) -> dict[str, str]:
    """Each trace pipeline's registers in `path`, as text; {} where it is missing."""
    if not path.exists():
        return {}
    cells = {}
    for pipeline in json.loads(path.read_text())["pipelines"]:
        if pipeline["pass"] != "trace" or not pipeline["executables"]:
            continue
        stats = pipeline["executables"][0]["statistics"]
        if "Register Count" in stats:
            cells[pipeline["variant"]] = f'{stats["Register Count"]:.0f}'
        elif "VGPRs" in stats:
            spilled = stats.get("Spilled VGPRs", 0)
            cells[pipeline["variant"]] = f'{stats["VGPRs"]:.0f}' + (f" + {spilled:.0f}" if spilled else "")
    return cells


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    folder, builds = Path(sys.argv[1]), sys.argv[2:]
    columns = []
    for build in builds:
        columns.append((f"{build} GPU", registers(folder / f"pipelines-{build}-gpu.json")))
        columns.append((f"{build} gfx1100", registers(folder / f"pipelines-{build}-gfx1100.json")))
    variants = []
    for _, cells in columns:
        variants += [v for v in cells if v not in variants]
    print("| trace pipeline | " + " | ".join(name for name, _ in columns) + " |")
    print("|---|" + "---|" * len(columns))
    for variant in variants:
        print(f"| {variant} | " + " | ".join(cells.get(variant, "-") for _, cells in columns) + " |")
    print("\nGPU: the driver's register count; gfx1100: VGPRs + spilled VGPRs (RADV's null device, wave64).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
