"""snell-usd render over every stage of a folder of public USD assets: what it refuses, and why.

    python3 bench/usd_corpus.py ROOT --json bench/results/usd-corpus-NAME.json [--size 160x120]

Runs `python -m snell.usd render STAGE -o OUT.png` with this interpreter (a venv with snell, usd-core and
MaterialX) for each .usd, .usda, .usdc and .usdz under ROOT, one at a time, each with a time limit, and
prints a table: exit code, seconds, warnings and the error a refused stage gave. A refusal is fair only where
USD itself cannot open the stage or its data is of the wrong type; the table's last column says which, by
opening each refused stage with pxr alone.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STAGES = (".usd", ".usda", ".usdc", ".usdz")


def usd_opens(path: Path) -> str:
    """'' where pxr opens the stage, else what it says."""
    done = subprocess.run([sys.executable, "-c", "import sys; from pxr import Usd; "
                           "sys.exit(0 if Usd.Stage.Open(sys.argv[1]) else 1)", str(path)],
                          capture_output=True, text=True, timeout=300)
    return "" if done.returncode == 0 else (done.stderr.strip().splitlines() or ["fails"])[-1][:160]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("root", type=Path)
    parser.add_argument("--json", type=Path, required=True)
    parser.add_argument("--size", default="160x120")
    parser.add_argument("--timeout", type=float, default=300.0)
    args = parser.parse_args()
    stages = sorted(p for p in args.root.rglob("*") if p.suffix.lower() in STAGES and p.is_file())
    rows = []
    with tempfile.TemporaryDirectory() as out:
        for i, stage in enumerate(stages):
            start = time.monotonic()
            try:
                done = subprocess.run([sys.executable, "-m", "snell.usd", "render", str(stage), "-o",
                                       f"{out}/frame.png", "--size", args.size], capture_output=True, text=True,
                                      timeout=args.timeout)
                code, said = done.returncode, done.stderr
            except subprocess.TimeoutExpired:
                code, said = -1, f"did not finish in {args.timeout:g} s"
            lines = said.strip().splitlines()
            error = next((line for line in lines if ": error: " in line), "" if code == 0 else (lines or [""])[-1])
            row = {"stage": str(stage.relative_to(args.root)), "exit": code,
                   "seconds": round(time.monotonic() - start, 2),
                   "warnings": sum(1 for line in lines if ": warning: " in line), "error": error[:300],
                   "tracebacks": said.count("Traceback")}
            if code != 0:
                row["usd_alone"] = usd_opens(stage) or "opens"
            rows.append(row)
            print(f"[{i + 1}/{len(stages)}] {row['exit']:>3} {row['seconds']:7.2f}s {row['stage']}"
                  f"{'  ' + row['error'] if code else ''}", flush=True)
    refused = [r for r in rows if r["exit"] != 0]
    unfair = [r for r in refused if r.get("usd_alone") == "opens"]
    print(f"\n{len(rows)} stages: {len(rows) - len(refused)} drawn, {len(refused)} refused "
          f"({len(unfair)} that USD itself opens), {sum(r['tracebacks'] for r in rows)} tracebacks")
    args.json.write_text(json.dumps({"root": str(args.root), "size": args.size, "stages": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
