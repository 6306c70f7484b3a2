"""`snell-usd`: USD stages from the command line, for pipelines (python -m snell.usd in a build tree).

    snell-usd info STAGE
    snell-usd render STAGE -o frames/shot.####.exr --frames 1001-1048 [--camera /World/cam] [--size 1920x1080]

Its conventions are `snell render`'s: the same frame lists and file names,
files that appear only when complete, --skip-existing, progress on standard
error, --quiet, and the same exit codes (0 done, 1 failed, 2 bad command
line, 128+N stopped by signal N).
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import time as clock
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from .. import Error, View, framing, methods, render_frames, version
from . import StageError, read
from ._cameras import CameraState
from ._frames import UsageError, check_frame_pattern, frame_path, parse_frames
from ._output import EXTENSIONS, OutputError, check_format, check_writable, write_image
from ._reader import StageContents
from ._screen import DEFAULT_TRIANGLE_BUDGET, refined_bytes, refined_size
from ._stage import scene_of, shot_frame, world_bounds

EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2

FOOTER = """\
exit codes: 0 done, 1 failed (the message says what), 2 bad command line,
  128+N stopped by signal N (SIGTERM: 143; the frames written are whole, the
  one under way is dropped)

environment:
  SNELL_DEVICE=INDEX|UUID|NAME  the device to use (as --device)
  SNELL_VALIDATION=1       turn on the Khronos validation layer; any message it
                           reports makes the exit code 1"""

RENDER_DESCRIPTION = """\
Renders a USD stage with snell: its meshes (skinned and blend-shaped by
UsdSkel), UsdPreviewSurface materials bound for --purpose (glass: opacity
below 1 refracts with its ior), UsdLux lights and a UsdGeomCamera. PNG is
written as 8-bit sRGB; EXR as linear half floats (or --float), with the
stage, time code and camera in its header. A file appears only once it is
complete. EXR needs OpenImageIO's Python module; PNG needs nothing more.

Frames are time codes: --frames takes the lists farms write (1001-1048,
1001-1048x2, 1001:1048:2, 1,5,10-20), each frame inside the stage's time
range unless --allow-outside-range. Only what moves is re-read from USD
and sent to the GPU each frame. Without --camera the stage's first camera
draws it; a stage without one gets snell render's framed view of its
bounds. --devices spreads the frames over GPUs through snell.render_frames,
as snell render --devices does (without a camera the shot is framed on its
first frame). SIGTERM or SIGINT drops the frame under way, keeps those
written and exits 128+N; --skip-existing then picks up where it stopped. A stage
snell cannot draw as it says (a mesh with faces but no points) is an error,
and nothing is written. A texture file that is missing or cannot be decoded
draws its input's fallback, and a stage with nothing to draw its background,
each with a warning; --strict makes them errors."""

INFO_DESCRIPTION = """\
Lists what snell reads from a stage: its units and time range, the meshes
drawn (with their parts and materials, skinning and deformation), the
materials bound for --purpose, cameras and lights (with snell's units), what
was skipped, and every warning. Exits 1 when the stage is broken where snell
needs it (a mesh with faces but no points; with --strict a texture that is missing
or cannot be decoded)."""


class _Parser(argparse.ArgumentParser):
    """argparse whose usage errors name the command and point at its --help (exit 2)."""

    def error(self, message: str) -> None:  # noqa: D401 (argparse's name)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n(see '{self.prog} --help')\n")


def _size(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not WIDTHxHEIGHT (e.g. 1920x1080)") from None
    if width <= 0 or height <= 0 or width > 16384 or height > 16384:
        raise argparse.ArgumentTypeError(f"'{text}': width and height must be 1 to 16384")
    return width, height


def _count(lowest: int, highest: float, what: str):
    """An argparse type: a whole number from lowest to highest (`_` and `,` may group its digits), else
    an error saying `what` it must be."""
    def parse(text: str) -> int:
        try:
            value = int(text.replace("_", "").replace(",", ""))
        except ValueError:
            value = lowest - 1
        if not lowest <= value <= highest:
            raise argparse.ArgumentTypeError(f"{what}, not '{text}'")
        return value
    return parse


_budget = _count(1, float("inf"), "a triangle budget is a positive count")
_level = _count(0, 8, "a subdivision level is 0 to 8")


def _number(text: str) -> float:
    """A command-line number, finite."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"'{text}' must be finite")
    return value


def _positive(text: str) -> float:
    value = _number(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"'{text}' must be a finite number above 0")
    return value



def _global_options(defaults: bool) -> argparse.ArgumentParser:
    """-q and --device, before the command or after it. After it they default to nothing (SUPPRESS), so
    a subcommand's parser does not overwrite what was given before the command."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("-q", "--quiet", action="store_true", default=False if defaults else argparse.SUPPRESS,
                        help="nothing on standard output, no progress and no warnings (errors still go to "
                             "standard error)")
    common.add_argument("--device", metavar="INDEX|NAME", default="" if defaults else argparse.SUPPRESS,
                        help="the GPU to render on (a device index or a name substring)")
    return common


def _parser() -> argparse.ArgumentParser:
    common = _global_options(defaults=False)
    reading = argparse.ArgumentParser(add_help=False)
    reading.add_argument("stage", metavar="STAGE", help="the stage: .usd, .usda, .usdc or .usdz")
    reading.add_argument("--purpose", choices=("preview", "full", "all"), default="preview",
                         help="the material purpose bound first (then the all-purpose binding); 'all': the "
                              "all-purpose binding alone (default preview)")
    reading.add_argument("--geometry-purpose", choices=("render", "proxy"), default="render",
                         help="the geometry drawn beside 'default' ('guide' never is; default render)")
    reading.add_argument("--meters-per-unit", type=_positive, metavar="M",
                         help="the stage's unit in metres, instead of its metersPerUnit")
    reading.add_argument("--subdiv-level", dest="subdivision_level", type=_level, default=None, metavar="N",
                         help="levels every subdivision surface's cage is refined by, on the GPU (0 to 8; 0 draws "
                              "the cages as they are; default: each cage's own, 1 to 3, its edges about a pixel "
                              "at --size through --camera)")
    reading.add_argument("--subdiv-budget", dest="triangle_budget", type=_budget, default=DEFAULT_TRIANGLE_BUDGET,
                         metavar="TRIANGLES",
                         help="refined triangles the sized levels may make before the largest meshes are refined "
                              f"fewer levels, with a warning (default {DEFAULT_TRIANGLE_BUDGET:,})")
    reading.add_argument("--strict", action="store_true",
                         help="a texture file that is missing or cannot be decoded, or a stage with nothing to "
                              "draw, is an error (by default a warning, and the texture's fallback or the "
                              "background is drawn, as usdview draws them)")

    parser = _Parser(prog="snell-usd", parents=[_global_options(defaults=True)],
                     formatter_class=argparse.RawDescriptionHelpFormatter,
                     description="snell-usd - USD stages drawn by snell (refraction through deforming meshes).\n"
                                 "Run 'snell-usd COMMAND --help' for a command's options.", epilog=FOOTER)
    parser.add_argument("--version", action="store_true", help="print snell's version and exit")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    info = commands.add_parser("info", parents=[common, reading], help="what snell reads from a stage",
                               description=INFO_DESCRIPTION, epilog=FOOTER,
                               formatter_class=argparse.RawDescriptionHelpFormatter)
    info.add_argument("--time", type=_number, metavar="T", help="the time code read (default: the stage's start)")
    info.add_argument("--json", action="store_true", help="print the listing as JSON")

    render = commands.add_parser("render", parents=[common, reading], help="render frames to EXR or PNG",
                                 description=RENDER_DESCRIPTION, epilog=FOOTER,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    render.add_argument("-o", "--output", required=True, metavar="FILE",
                        help="the image to write: .exr or .png; with several frames the name holds the frame "
                             "number: '#'s (shot.####.exr: shot.1001.exr) or a printf %%04d")
    render.add_argument("--frames", metavar="LIST",
                        help="the time codes to render: 1001-1048, 1001-1048x2 (every 2nd), 1001:1048:2, "
                             "1,5,10-20 (default: the stage's start)")
    render.add_argument("--camera", metavar="PRIM", help="the UsdGeomCamera to render through (default: the "
                                                         "stage's first; none: a framed view of the bounds)")
    render.add_argument("--size", type=_size, default=(1920, 1080), metavar="WxH",
                        help="the image's size in pixels (default 1920x1080)")
    render.add_argument("--conform", default="expandAperture",
                        choices=("expandAperture", "cropAperture", "adjustApertureWidth", "adjustApertureHeight"),
                        help="how the camera's aperture meets the image's aspect (UsdRender's rules; default "
                             "expandAperture)")
    render.add_argument("--method", default="auto", metavar="M",
                        help="how refraction is drawn, as snell render's --method (default auto)")
    render.add_argument("--float", dest="float_pixels", action="store_true",
                        help="with an .exr: 32-bit float channels instead of half")
    render.add_argument("--skip-existing", action="store_true",
                        help="leave frames whose file exists alone: files appear only when complete, so an "
                             "existing one is a finished frame")
    render.add_argument("--allow-outside-range", action="store_true",
                        help="render frames outside the stage's time range (USD holds the nearest samples)")
    render.add_argument("--devices", metavar="LIST",
                        help="render on several devices, a worker each, as snell render --devices: all (every "
                             "GPU), or device indices (0,1; 0,0 runs two workers on one device); each takes the "
                             "next frame as it finishes one, and the pixels are those one device writes")
    return parser


# ---------------------------------------------------------------- output


class _Console:
    """Standard output and error as --quiet allows."""

    def __init__(self, quiet: bool) -> None:
        self.quiet = quiet

    def out(self, text: str) -> None:
        if not self.quiet:
            print(text, flush=True)

    def progress(self, text: str) -> None:
        if not self.quiet:
            print(text, file=sys.stderr, flush=True)

    def warnings(self, items: Sequence[Any]) -> None:
        for item in items:
            if not item.error:
                self.progress(f"snell-usd: warning: {item}")

    @staticmethod
    def error(text: str) -> None:
        print(f"snell-usd: error: {text}", file=sys.stderr, flush=True)


# ---------------------------------------------------------------- info


def _info(args: argparse.Namespace, console: _Console) -> int:
    contents = read(args.stage, time=args.time, purpose=args.purpose, geometry_purpose=args.geometry_purpose,
                    meters_per_unit=args.meters_per_unit, load_textures=False, missing_textures_fail=args.strict,
                    subdivision_level=args.subdivision_level, triangle_budget=args.triangle_budget)
    listing = _listing(contents)
    if args.json:
        print(json.dumps(listing, indent=2))
    elif not console.quiet:
        _print_listing(listing)
    return EXIT_FAILURE if contents.problems.errors else EXIT_OK


def _refined(source) -> dict[str, Any]:
    """A cage's scheme and level, and what its refinement holds (whole cage, every part together)."""
    t, cage = source.topology, source.cage
    vertices, triangles = refined_size(t.face_counts, t.face_points, cage.scheme, cage.level)
    return {"scheme": cage.scheme, "level": cage.level, "vertices": vertices, "triangles": triangles,
            "bytes": refined_bytes(vertices, triangles)}


def _drawn(part, source) -> dict[str, Any]:
    """What a part draws: its refined vertices and triangles where it is a cage's (its faces refined), else its
    own; a cage's own counts beside them."""
    if part.cage is None:
        return {"vertices": len(part.vertex_point), "triangles": len(part.triangles)}
    t = source.topology
    faces = np.unique(t.triangle_face[part.triangles])
    vertices, _ = refined_size(t.face_counts, t.face_points, part.cage.scheme, part.cage.level)
    counts = t.face_counts[faces]
    starts = (np.cumsum(t.face_counts) - t.face_counts)[faces]
    points = np.concatenate([t.face_points[s:s + c] for s, c in zip(starts, counts)]) if len(faces) else []
    _, triangles = refined_size(counts, points, part.cage.scheme, part.cage.level)
    return {"vertices": vertices, "triangles": triangles, "cage_vertices": t.point_count,
            "cage_triangles": len(part.triangles)}


def _listing(contents: "StageContents") -> dict[str, Any]:
    materials = contents.materials.records
    meshes = []
    for source in contents.sources:
        placements = [p for p in contents.placements if p.source is source]
        t = source.topology
        entry = {
            "prim": source.path, "points": t.point_count, "faces": t.face_count,
            "triangles": int(sum(len(p.triangles) for p in source.parts)),
            "normals": (source.normals.interpolation if source.normals is not None else
                        "snell's, of the refined surface" if source.cage is not None else "computed (smooth)"),
            "subdivision": (_refined(source) if source.cage is not None else None),
            "skeleton": str(source.skin.skeleton_prim.GetPath()) if source.skin is not None else None,
            "deforms": source.deforms, "moves": any(p.varying for p in placements), "instances": len(placements),
            "parts": [{"name": part.name, "material": materials[part.material].path or "(none)",
                       **_drawn(part, source)} for part in source.parts],
        }
        meshes.append(entry)
    cameras = []
    for prim in contents.cameras:
        state = None
        try:
            state = contents.camera(str(prim.GetPath()), contents.time)
        except Exception as e:  # a camera that makes no picture is listed with its problem
            cameras.append({"prim": str(prim.GetPath()), "problem": str(e)})
            continue
        cameras.append({"prim": state.path, "description": state.describe()})
    return {
        "stage": contents.path,
        "up_axis": contents.up_axis,
        "meters_per_unit": contents.meters_per_unit,
        "meters_per_unit_authored": contents.meters_per_unit_authored,
        "time_range": [contents.start, contents.end] if contents.has_range else None,
        "time_codes_per_second": contents.time_codes_per_second,
        "time_code": contents.time,
        "material_purpose": contents.options.purpose,
        "geometry_purpose": contents.options.geometry_purpose,
        "meshes": meshes,
        "snell_meshes": sum(len(s.parts) for s in contents.sources),
        "materials": [{"prim": r.path or "(none)", "double_sided": r.double_sided, "description": r.summary}
                      for r in materials],
        "cameras": cameras,
        "lights": [{"prim": r.path, "type": r.kind, "snell": r.summary} for r in contents.lights],
        "skipped": contents.skipped,
        "warnings": [{"prim": w.prim, "message": w.message, "error": w.error} for w in contents.problems.items],
    }


def _print_listing(i: dict[str, Any]) -> None:
    unit = f"{i['meters_per_unit']:g}" + (" (authored)" if i["meters_per_unit_authored"] else " (USD's fallback)")
    span = (f"time codes {i['time_range'][0]:g}-{i['time_range'][1]:g}" if i["time_range"] else "no time range")
    print(f"stage {i['stage']}")
    print(f"  up axis {i['up_axis']}, metres per unit {unit}, {span} at {i['time_codes_per_second']:g} per "
          f"second, read at time code {i['time_code']:g}")
    moving = sum(1 for m in i["meshes"] if m["deforms"] or m["moves"])
    print(f"meshes: {len(i['meshes'])} read, {i['snell_meshes']} snell meshes, {moving} move or deform "
          f"(geometry purpose {i['geometry_purpose']})")
    for m in i["meshes"]:
        motion = [w for w, on in (("deforms", m["deforms"]), ("moves", m["moves"])) if on]
        skinned = f", skinned by {m['skeleton']}" if m["skeleton"] else ""
        shared = f", {m['instances']} instances" if m["instances"] > 1 else ""
        sub = m["subdivision"]
        refined = (f", a {sub['scheme']} subdivision surface refined {sub['level']} "
                   f"level{'s' if sub['level'] != 1 else ''} on the GPU to "
                   f"{sub['vertices']} vertices and {sub['triangles']} triangles (about "
                   f"{sub['bytes'] / 2 ** 20:.1f} MiB)" if sub else "")
        print(f"  {m['prim']}: {m['points']} points, {m['faces']} faces ({m['triangles']} triangles){refined}, "
              f"normals {m['normals']}{skinned}{shared}{', ' + ' and '.join(motion) if motion else ', static'}")
        for part in m["parts"]:
            cage = (f" (its cage {part['cage_vertices']} vertices, {part['cage_triangles']} triangles)"
                    if "cage_vertices" in part else "")
            print(f"    {part['name']}: {part['vertices']} vertices, {part['triangles']} triangles{cage}, "
                  f"material {part['material']}")
    print(f"materials (purpose {i['material_purpose']}): {len(i['materials'])}")
    for m in i["materials"]:
        print(f"  {m['prim']}{' (double-sided)' if m['double_sided'] else ''}: {m['description']}")
    print(f"cameras: {len(i['cameras'])}" + ("" if i["cameras"] else " (a framed view of the bounds is drawn)"))
    for c in i["cameras"]:
        print(f"  {c['prim']}: {c.get('description') or c.get('problem')}")
    print(f"lights: {len(i['lights'])}" + ("" if i["lights"] else " (snell's headlight is drawn)"))
    for light in i["lights"]:
        print(f"  {light['prim']} ({light['type']}): {light['snell']}")
    for kind, paths in i["skipped"].items():
        print(f"skipped, {kind}: {len(paths)} ({', '.join(paths[:4])}{', ...' if len(paths) > 4 else ''})")
    print(f"warnings: {len(i['warnings'])}")
    for w in i["warnings"]:
        where = f"{w['prim']}: " if w["prim"] else ""
        print(f"  {'error: ' if w['error'] else ''}{where}{w['message']}")


# ---------------------------------------------------------------- render

_stop_signal = 0


def _on_stop(signum: int, _frame: object) -> None:
    global _stop_signal
    _stop_signal = signum


def _check_render_options(args: argparse.Namespace) -> Optional[list[int]]:
    """The options' own checks (UsageError); the frames asked for, or None for the stage's start."""
    suffix = Path(args.output).suffix.lower()
    if suffix not in EXTENSIONS:
        raise UsageError(f"-o {args.output}: must end in .exr or .png")
    if args.float_pixels and suffix != ".exr":
        raise UsageError(f"--float needs an .exr output, got '{args.output}'")
    names = [name for name, _ in methods()]
    if args.method != "auto" and args.method not in names:
        raise UsageError(f"--method takes auto or one of {', '.join(names)}, got '{args.method}'")
    if args.devices is not None and (not args.devices or args.devices.startswith(",") or
                                     args.devices.endswith(",") or ",," in args.devices):
        raise UsageError(f"--devices {args.devices}: give all, or device indices separated by commas (0,1)")
    if args.frames is None:
        return None
    frames = parse_frames("--frames", args.frames)
    check_frame_pattern("-o", args.output, len(frames))
    return frames


def _unfinished(frames: list[int], args: argparse.Namespace, console: _Console) -> list[int]:
    """--skip-existing: the frames whose file is not there (files appear only whole)."""
    if not args.skip_existing:
        return frames
    left = [f for f in frames if not Path(frame_path(args.output, f)).is_file()]
    if len(left) < len(frames):
        console.out(f"skipping {len(frames) - len(left)} of {len(frames)} frames: their files exist")
    return left


def _render(args: argparse.Namespace, console: _Console) -> int:
    frames = _check_render_options(args)
    try:
        check_format(args.output)  # EXR without OpenImageIO fails before any work
    except OutputError as e:
        raise StageError(str(e)) from None
    if frames is not None:
        frames = _unfinished(frames, args, console)
        if not frames:
            return EXIT_OK
    contents = read(args.stage, time=frames[0] if frames else None, purpose=args.purpose,
                    geometry_purpose=args.geometry_purpose, meters_per_unit=args.meters_per_unit,
                    missing_textures_fail=args.strict, subdivision_level=args.subdivision_level,
                    image_size=args.size, camera=args.camera, triangle_budget=args.triangle_budget)
    if contents.problems.errors:  # a stage broken where snell needs it: nothing is drawn
        raise StageError(f"{contents.path}: {contents.problems.errors[0]}".replace(": error: ", ": ", 1))
    if frames is None:
        if not float(contents.time).is_integer():
            raise StageError(f"{contents.path}: its start time code {contents.time:g} is not a whole frame: "
                             "give --frames")
        frames = _unfinished([int(contents.time)], args, console)
        if not frames:
            return EXIT_OK
    outside = [f for f in frames if not contents.in_range(f)]
    if outside and not args.allow_outside_range:
        shown = ", ".join(str(f) for f in outside[:5]) + (", ..." if len(outside) > 5 else "")
        raise StageError(f"{contents.path}: frames {shown} are outside the stage's time range "
                         f"{contents.start:g}-{contents.end:g} (--allow-outside-range renders USD's held samples)")
    if args.camera is not None:
        try:
            contents.camera(args.camera, frames[0])  # an unknown camera fails before any GPU work
        except StageError as e:
            raise UsageError(f"--camera {args.camera}: {e}") from None
    try:
        check_writable(frame_path(args.output, frames[0]))
    except OutputError as e:
        raise StageError(str(e)) from None
    console.warnings(contents.problems.items)
    return _draw(contents, frames, args, console)


class _Writer:
    """Writes each frame's picture (with its EXR header) and says so, counting what it wrote."""

    def __init__(self, contents: "StageContents", frames: list[int], args: argparse.Namespace,
                 console: _Console) -> None:
        self.contents, self.frames, self.args, self.console = contents, frames, args, console
        self.written = 0
        self.started = clock.perf_counter()
        self.camera_name = args.camera or (str(contents.cameras[0].GetPath()) if contents.cameras
                                           else "a framed view of the bounds")

    def write(self, frame: int, rgba: np.ndarray, device_name: str, camera: Optional[CameraState],
              seconds: float) -> None:
        path = frame_path(self.args.output, frame)
        metadata: dict[str, Any] = {"Software": f"snell-usd {version()}"}
        if path.lower().endswith(".exr"):
            metadata.update({"snell:stage": self.contents.path, "snell:timeCode": float(frame),
                             "snell:camera": self.camera_name, "snell:device": device_name,
                             "snell:materialPurpose": self.args.purpose})
            if camera is not None:  # OpenEXR's worldToCamera: row vectors, translation in the last row
                metadata["worldToCamera"] = np.linalg.inv(camera.camera_to_world).T.astype(np.float32)
        try:
            write_image(path, rgba, float_pixels=self.args.float_pixels, metadata=metadata)
        except OutputError as e:
            raise StageError(str(e)) from None
        self.written += 1
        width, height = self.args.size
        if len(self.frames) > 1:
            self.console.progress(f"frame {frame} ({self.written}/{len(self.frames)}) -> {path}, {seconds:.2f} s")
        else:
            self.console.out(f"wrote {path}: {width}x{height}, camera {self.camera_name}, time code {frame}, "
                             f"{device_name}, {seconds:.2f} s")

    def finish(self, where: str, messages: int) -> int:
        """The exit code, once the frames are done or a signal stopped them."""
        if _stop_signal:
            self.console.error(f"render: stopped by signal {_stop_signal}; the {self.written} frames written are "
                               "whole, the one under way was dropped")
            return 128 + _stop_signal
        if len(self.frames) > 1:
            self.console.out(f"{self.written} frames in {clock.perf_counter() - self.started:.1f} s on {where}")
        if messages:
            self.console.error(f"the Khronos validation layer reported {messages} messages")
            return EXIT_FAILURE
        return EXIT_OK


class _Stopped(Exception):
    """A signal came during a shot on several devices: render_frames stops and raises this."""


def _draw(contents: "StageContents", frames: list[int], args: argparse.Namespace, console: _Console) -> int:
    """Renders the frames as one shot with snell.render_frames: on the device --device names, or a worker per
    device of --devices (as snell render --devices). Each frame's posed meshes, moved instances and camera go
    with it, and its picture comes back here, on this thread, to be written. A signal drops the frames under way
    and exits 128 + N."""
    global _stop_signal
    said = len(contents.problems.items)
    validation = os.environ.get("SNELL_VALIDATION") == "1"
    width, height = args.size
    scene, meshes = scene_of(contents)
    options = {"method": args.method, "environment": contents.snell_environment()}
    first = contents.camera(args.camera, frames[0])
    if first is not None:
        view_matrix, projection = first.matrices(width, height, args.conform)
        view = View(width, height, view_matrix=view_matrix, projection=projection, **options)
    else:  # no camera: the whole shot is framed on the first frame's bounds (the stage is read at that frame)
        view = View(width, height, **framing(*world_bounds(contents, lambda mesh: meshes[mesh].positions)),
                    **options)
    writer = _Writer(contents, frames, args, console)
    cameras: dict[int, Optional[CameraState]] = {}
    started: dict[int, float] = {}

    def poses():
        for frame in frames:
            if _stop_signal:
                raise _Stopped()
            started[frame] = clock.perf_counter()
            cameras[frame] = contents.camera(args.camera, frame)
            yield shot_frame(contents, frame, cameras[frame], width, height, args.conform)

    def keep(picture: dict) -> None:
        if _stop_signal:
            raise _Stopped()
        frame = int(picture["number"])
        writer.write(frame, picture["rgba"], picture["device"], cameras.pop(frame, None),
                     clock.perf_counter() - started.pop(frame, writer.started))

    _stop_signal = 0
    previous = {s: signal.signal(s, _on_stop) for s in (signal.SIGINT, signal.SIGTERM)}
    messages, where = 0, args.devices or args.device or "the first device"
    try:
        summary = render_frames(scene, view, poses(), keep, devices=args.devices or "", device=args.device,
                                validation=validation)
        messages = sum(int(w["validation_messages"]) for w in summary["workers"])
        where = ", ".join(f"{w['device']} ({w['frames']})" for w in summary["workers"])
    except _Stopped:
        pass
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        scene.close()
    console.warnings(contents.problems.items[said:])
    return writer.finish(where, messages)


# ---------------------------------------------------------------- main


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs `snell-usd` with argv (default: the process's arguments); returns the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.version:
        print(f"snell-usd {version()}")
        return EXIT_OK
    if args.command is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    console = _Console(args.quiet)
    try:
        return _info(args, console) if args.command == "info" else _render(args, console)
    except UsageError as e:
        console.error(f"{args.command}: {e}\n(see 'snell-usd {args.command} --help')")
        return EXIT_USAGE
    except (Error, ValueError) as e:  # StageError included: it names the file and the prim
        console.error(str(e))
        return EXIT_FAILURE
