"""The snell module's per-frame cost for the Blender add-on's feed, replayed without Blender.

    python3 bench/python_frame.py FEED_FOLDER [--frames 48] [--json out.json]

FEED_FOLDER holds feed.npz from bench/record_blender_feed.py. Each frame
writes the recorded evaluated vertices of the meshes that deformed into
snell's mapped memory (the numpy views), marks them dirty and renders the
viewport composite at the recorded camera and size, two ways:

  image back  Renderer.render: the picture comes back as a numpy array
  interop     Renderer.render_to a SharedImage: the picture stays on the GPU

It prints a table of medians (wall time per stage, and snell's own GPU pass
times) and writes them, with every frame's figures, as JSON.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import snell

args = sys.argv[1:]
FOLDER = Path(args[0])
FRAMES = int(args[args.index("--frames") + 1]) if "--frames" in args else 48
JSON = args[args.index("--json") + 1] if "--json" in args else ""

with np.load(FOLDER / "feed.npz") as stored:
    feed = {key: stored[key] for key in stored.files}  # in memory: an npz decompresses on every read
about = json.loads(bytes(feed["description"]).decode())
meshes = [snell.Mesh(feed[f"mesh{i}_positions"], feed[f"mesh{i}_normals"], feed[f"mesh{i}_indices"],
                     feed[f"mesh{i}_uvs"] if f"mesh{i}_uvs" in feed else None, material=m["material"], name=m["name"])
          for i, m in enumerate(about["meshes"])]
materials = [snell.Material(**m) for m in about["materials"]]
textures = [snell.Texture(feed[f"texture{i}"]) for i in range(sum(1 for k in feed if k.startswith("texture")))]
lights = [snell.Light(**light) for light in about["lights"]]
instances = [snell.Instance(mesh, feed[f"instance{i}"]) for i, mesh in enumerate(about["instance_meshes"])]
width, height = about["size"]
recorded = about["frames"]


def replay(device, way: str) -> dict:
    scene = snell.Scene.from_arrays(meshes, materials=materials, textures=textures, lights=lights,
                                    instances=instances, name="demo eye rig (Blender's feed)")
    renderer = snell.Renderer(device, scene)
    view = snell.View(width, height, view_matrix=feed["view_matrix"], projection=feed["projection"], viewport=True,
                      background=about["background"])
    views = {i: (renderer.positions(i), renderer.normals(i)) for i in range(len(meshes))}
    image = snell.SharedImage(device, width, height) if way == "interop" else None
    out = np.empty((height, width, 4), np.float32)
    rows = []
    # Two seconds of frames first: pipelines, buffers, and a GPU that left its idle clocks.
    warm_until, step, warmup = time.perf_counter() + 2.0, 0, 0
    while step < FRAMES + warmup:
        if time.perf_counter() < warm_until:
            warmup += 1
        frame = recorded[step % len(recorded)]["frame"]
        started = time.perf_counter()
        sent = 0
        for i, (positions, normals) in views.items():
            key = f"frame{frame}_positions{i}"
            if key in feed:
                np.copyto(positions, feed[key])
                np.copyto(normals, feed[f"frame{frame}_normals{i}"])
                renderer.mark_dirty(i)
                sent += 1
        fed = time.perf_counter()
        if image is not None:
            renderer.render_to(view, image)
        else:
            renderer.render_into(view, out)
        done = time.perf_counter()
        info = renderer.last_frame()
        step += 1
        if step > warmup:
            rows.append({"frame": frame, "meshes": sent, "feed": (fed - started) * 1000,
                         "render": (done - fed) * 1000, "total": (done - started) * 1000, "gpu": info["gpu_ms"],
                         "pass_ms": info["pass_ms"]})
    renderer.close()
    return {"way": way, "median_ms": {k: statistics.median(r[k] for r in rows)
                                      for k in ("feed", "render", "gpu", "total")}, "frames": rows}


with snell.Device(interop=True) as device:
    report = {"device": device.name, "size": [width, height], "frames": FRAMES,
              "command": "python3 bench/python_frame.py " + " ".join(args),
              "results": [replay(device, "image back"), replay(device, "interop")]}
print(f"the snell module replaying the Blender add-on's feed of the demo eye rig, {width}x{height} viewport "
      f"composite, {report['device']}, medians of {FRAMES} frames (ms)")
print(f"{'way':12s}{'feed':>10s}{'render':>10s}{'gpu':>10s}{'total':>10s}")
for r in report["results"]:
    print(f"{r['way']:12s}" + "".join(f"{r['median_ms'][k]:10.3f}" for k in ("feed", "render", "gpu", "total")))
if JSON:
    Path(JSON).write_text(json.dumps(report, indent=1) + "\n")
    print(f"wrote {JSON}")
