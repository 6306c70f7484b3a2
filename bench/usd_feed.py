"""snell.usd's cost: a stage's load, and each frame's feed split into USD's evaluation, the copy into snell,
and the render.

    python bench/usd_feed.py [--frames 48] [--size 640x360] [--rings 24 --segments 32] [--stage STAGE]
                             [--viewport] [--json out.json]

Without --stage it writes the rigged eye pair of tests/usd (eye_stage.py: two
skinned eyeballs with a glass cornea subset, two iris discs with a pupil blend
shape, a UsdSkel gaze, an iris texture, three lights, a camera) into a
temporary folder; --rings and --segments make its meshes denser. Load is
split into USD's read (traversal, topology, bindings, materials, textures:
snell.usd.read), the scene and renderer build (Scene.from_arrays, Renderer),
and the first frame (pipelines, trees). Each frame then steps one time code
through the stage's range and is split into

  evaluate  USD: points, UsdSkel skinning and blend shapes, normals (Stage.contents.evaluate)
  copy      into snell's mapped memory, mark_dirty, transforms (Stage.send)
  render    Renderer.render (wall), of which snell's GPU passes (last_frame()['gpu_ms'])

printed as medians of --frames frames after two seconds of warm-up, and
written with every frame's figures as JSON.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

from pxr import Usd  # noqa: F401  (before snell: see below)

import snell
import snell.usd

# usd-core loads first: on the GPU machine (its own CPython 3.12, GCC 13 and
# pybind11, snell's module built there) importing pxr after snell's module
# crashes in pxr's import, and before it does not.

HERE = Path(__file__).resolve().parent


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=48, help="frames measured (default 48)")
    parser.add_argument("--size", default="640x360", help="the picture, WIDTHxHEIGHT (default 640x360)")
    parser.add_argument("--rings", type=int, default=24, help="the eye pair's eyeball rings (default 24)")
    parser.add_argument("--segments", type=int, default=32, help="and segments round (default 32)")
    parser.add_argument("--stage", help="measure this stage instead of the eye pair")
    parser.add_argument("--viewport", action="store_true", help="render the viewport composite, not the trace")
    parser.add_argument("--no-textures", action="store_true",
                        help="read the stage without its textures (a machine without OpenImageIO, as the GPU machine "
                             "is: each texture is a 1x1 stand-in, which no per-frame column reads)")
    parser.add_argument("--json", help="write the report here")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))

    with tempfile.TemporaryDirectory() as folder:
        if args.stage:
            stage_path, about = Path(args.stage), {"stage": args.stage}
        else:
            sys.path[:0] = [str(HERE.parent / "tests" / "usd"), str(HERE.parent / "tests")]
            from eye_stage import eye_arrays, write_eye_stage

            written = write_eye_stage(Path(folder), eye_arrays(args.rings, args.segments))
            stage_path, about = written.usd, {"stage": "tests/usd eye pair", "rings": args.rings,
                                              "segments": args.segments}
        with snell.Device() as device:
            report = run(device, stage_path, width, height, args.frames, args.viewport, not args.no_textures)
    report.update(about)
    report["command"] = "python bench/usd_feed.py " + " ".join(sys.argv[1:])
    print_table(report)
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=1) + "\n")
        print(f"wrote {args.json}")
    return 0


def run(device: snell.Device, path: Path, width: int, height: int, frames: int, viewport: bool,
        textures: bool = True) -> dict:
    started = time.perf_counter()
    contents = snell.usd.read(path, load_textures=textures)
    read_s = time.perf_counter() - started
    built = time.perf_counter()
    stage = snell.usd.Stage(contents, device=device)
    build_s = time.perf_counter() - built
    first = time.perf_counter()
    view = stage.view(width, height, viewport=viewport)
    stage.renderer.render(view)
    first_s = time.perf_counter() - first
    start, end = stage.time_range or (contents.time, contents.time + 47)
    span = int(end - start) + 1
    rows, step, warmup = [], 0, 0
    warm_until = time.perf_counter() + 2.0  # pipelines, caches and allocations settle first
    while len(rows) < frames:
        t = start + (step % span)
        step += 1
        began = time.perf_counter()
        frame = contents.evaluate(t)
        evaluated = time.perf_counter()
        feed = stage.send(frame)
        stage.time = t
        copied = time.perf_counter()
        stage.renderer.render(stage.view(width, height, viewport=viewport))
        rendered = time.perf_counter()
        if rendered < warm_until:
            warmup += 1
            continue
        info = stage.renderer.last_frame()
        rows.append({"time_code": t, "meshes_sent": feed.meshes, "transforms_sent": feed.transforms,
                     "evaluate": (evaluated - began) * 1e3, "copy": (copied - evaluated) * 1e3,
                     "render": (rendered - copied) * 1e3, "gpu": info["gpu_ms"],
                     "total": (rendered - began) * 1e3, "pass_ms": info["pass_ms"]})
    facts = {"meshes_read": len(contents.sources), "snell_meshes": stage.scene.mesh_count,
             "vertices": sum(len(p.vertex_point) for s in contents.sources for p in s.parts),
             "deforming_vertices": sum(len(p.vertex_point) for s in contents.dynamic_sources for p in s.parts),
             "points_skinned": sum(s.topology.point_count for s in contents.dynamic_sources if s.skin is not None)}
    stage.close()
    keys = ("evaluate", "copy", "render", "gpu", "total")
    return {"device": device.name, "size": [width, height], "output": "viewport" if viewport else "trace",
            "textures": textures,
            "frames": frames, "warmup_frames": warmup, **facts,
            "load_s": {"read": read_s, "build": build_s, "first_frame": first_s, "total": read_s + build_s + first_s},
            "median_ms": {k: statistics.median(r[k] for r in rows) for k in keys}, "per_frame": rows}


def print_table(r: dict) -> None:
    load = r["load_s"]
    print(f"snell.usd on {r['device']}: {r['stage']}, {r['snell_meshes']} snell meshes, {r['vertices']} vertices "
          f"({r['deforming_vertices']} deforming), {r['size'][0]}x{r['size'][1]} {r['output']}")
    print(f"load: read {load['read'] * 1e3:.1f} ms, scene and renderer {load['build'] * 1e3:.1f} ms, first frame "
          f"{load['first_frame'] * 1e3:.1f} ms, total {load['total'] * 1e3:.1f} ms")
    print(f"per frame, medians of {r['frames']} frames (ms):")
    print(f"{'evaluate':>10s}{'copy':>10s}{'render':>10s}{'of it GPU':>11s}{'total':>10s}")
    m = r["median_ms"]
    print(f"{m['evaluate']:10.3f}{m['copy']:10.3f}{m['render']:10.3f}{m['gpu']:11.3f}{m['total']:10.3f}")


if __name__ == "__main__":
    sys.exit(main())
