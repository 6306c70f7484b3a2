"""The table of bench/compare.sh: each build's median over the rounds, with its spread.

    python3 bench/compare_table.py compare.log [--json compare.json] [--order "base new"]

The log holds, per measurement, a line `@@ round=R build=B row=ROW` and the line
the benchmark printed: `rays per second, ... 1.009x (trace 1.6400 ms, driver
1.6550 ms)` for trace rows, `refraction  0.2220 ...` for viewport rows. Each
row shows every build's median time, its spread (min-max over rounds), the
trace rows' ratio against driver-rt (rays per second, the driver's time over
snell's, the median of the rounds' ratios), and every build's change against
the first build; a change over 2% is marked.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
from collections import defaultdict

HEAD = re.compile(r"^@@ round=(\d+) build=(\S+) row=(\S+)")
RAYS = re.compile(r"rays per second.*?: ([0-9.]+)x \(trace ([0-9.]+) ms, driver ([0-9.]+) ms\)")
REFRACTION = re.compile(r"^refraction\s+([0-9.]+)")
HASH = re.compile(r"^image hash (\S*)")


def parse(lines: list[str]) -> dict:
    """{row: {build: [{'ms': .., 'driver_ms': .., 'ratio': ..}, ...]}} in the log's order."""
    found: dict = defaultdict(lambda: defaultdict(list))
    current = None
    for line in lines:
        head = HEAD.match(line)
        if head:
            current = (head.group(3), head.group(2))
            continue
        if current is None:
            continue
        rays = RAYS.search(line)
        refraction = REFRACTION.match(line)
        image = HASH.match(line)
        if image:
            found[current[0]][current[1]].append({"hash": image.group(1)})
        elif rays:
            found[current[0]][current[1]].append(
                {"ms": float(rays.group(2)), "driver_ms": float(rays.group(3)), "ratio": float(rays.group(1))})
        elif refraction:
            found[current[0]][current[1]].append({"ms": float(refraction.group(1))})
    return found


def summary(runs: list[dict]) -> dict:
    if "hash" in runs[0]:
        return {"hash": runs[0]["hash"]}
    ms = [r["ms"] for r in runs]
    out = {"median_ms": statistics.median(ms), "min_ms": min(ms), "max_ms": max(ms), "rounds": len(ms)}
    if "ratio" in runs[0]:
        out["ratio_vs_driver_rt"] = statistics.median(r["ratio"] for r in runs)
        out["driver_median_ms"] = statistics.median(r["driver_ms"] for r in runs)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("log")
    parser.add_argument("--json")
    parser.add_argument("--order", default="", help="the builds in column order (default: as first seen)")
    args = parser.parse_args()
    with open(args.log) as f:
        found = parse(f.read().splitlines())
    if not found:
        raise SystemExit(f"{args.log}: no measurements (did every build run?)")
    builds = args.order.split() or list(dict.fromkeys(b for row in found.values() for b in row))
    table = {row: {b: summary(runs[b]) for b in builds if runs.get(b)} for row, runs in found.items()}

    base = builds[0]
    hashes = {row: cells for row, cells in table.items() if any("hash" in c for c in cells.values())}
    for row in hashes:
        del table[row]
    header = ["row"] + [f"{b} ms (spread)" for b in builds] + [f"{b} vs {base}" for b in builds[1:]]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row, cells in table.items():
        line = [row]
        for b in builds:
            c = cells.get(b)
            if not c:
                line.append("-")
                continue
            text = f"{c['median_ms']:.3f} ({c['min_ms']:.3f}-{c['max_ms']:.3f})"
            if "ratio_vs_driver_rt" in c:
                text += f", **{c['ratio_vs_driver_rt']:.3f}x** driver-rt"
            line.append(text)
        for b in builds[1:]:
            if base not in cells or b not in cells:
                line.append("-")
                continue
            change = cells[b]["median_ms"] / cells[base]["median_ms"] - 1.0
            line.append(f"{100 * change:+.1f}%" + (" (moved)" if abs(change) > 0.02 else ""))
        print("| " + " | ".join(line) + " |")
    for row, cells in hashes.items():
        same = [b for b in builds[1:] if b in cells and base in cells and cells[b]["hash"] == cells[base]["hash"]]
        differ = [b for b in builds[1:] if b in cells and b not in same]
        print(f"{row}: " + ("same pixels as " + base + ": " + ", ".join(same) if same else "") +
              ("; different pixels: " + ", ".join(differ) if differ else ""))
    print("\n(ms: the median over rounds of each run's median frame; trace rows: snell's trace pass, its ratio the"
          " driver's trace time over snell's; viewport rows: the refraction work of a frame)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"schema": "snell.bench-compare/1", "builds": builds, "rows": table, "pixels": hashes,
                       "runs": found}, f, indent=1)


if __name__ == "__main__":
    main()
