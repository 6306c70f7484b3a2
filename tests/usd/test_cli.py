"""`snell-usd info` and `snell-usd render` (run as python -m snell.usd)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import numpy as np
import pytest
from pxr import UsdGeom

from conftest import read_image, snell_usd, snell_usd_ok
from stages import bind, new_stage, preview_material, quad, texture

SIZE = "64x48"


def test_info_lists_prims_materials_cameras_lights_and_the_time_range(eyes):
    done = snell_usd_ok("info", eyes.usd)
    out = done.stdout
    assert "time codes 1-48 at 24 per second" in out and "metres per unit 1 (authored)" in out
    assert "/World/Rig/EyeballL (cornea): 193 vertices, 352 triangles, material /World/Looks/Cornea" in out
    assert "skinned by /World/Rig/Skel" in out
    assert "/World/Looks/Cornea: UsdPreviewSurface, glass (opacity 0, ior 1.376)" in out
    assert "/World/Camera: focal length 35" in out
    assert "/World/Key (SphereLight): point, 251.3 cd" in out and "/World/Rim (SphereLight): spot" in out
    # Only the approximation of the rig's two sphere lights as points.
    assert "warnings: 2" in out and out.count("shines as a point light at its centre") == 2, out


def test_info_json_is_the_same_listing(eyes):
    done = snell_usd("info", eyes.usd, "--json", "--purpose", "full")
    listing = json.loads(done.stdout)
    assert listing["time_range"] == [1.0, 48.0] and listing["material_purpose"] == "full"
    materials = {"/World/Looks/ScleraFull", "/World/Looks/CorneaFull", "/World/Looks/IrisAllPurpose"}
    assert {m["prim"] for m in listing["materials"]} == materials
    assert [c["prim"] for c in listing["cameras"]] == ["/World/Camera"] and len(listing["lights"]) == 3


def broken_stage(folder) -> object:
    """A card whose material's texture file is not there: broken.usda in `folder`."""
    stage = new_stage(folder / "broken.usda")
    card = quad(stage, "/World/Card")
    material = preview_material(stage, "/World/M")
    texture(stage, material, "./gone.png")
    bind(card.GetPrim(), material)
    stage.GetRootLayer().Save()
    return folder / "broken.usda"


def test_info_on_a_broken_stage_lists_the_error_and_exits_1(tmp_path):
    done = snell_usd("info", broken_stage(tmp_path), "--strict")
    assert done.returncode == 1
    assert "  error: /World/M/Texture_diffuseColor: texture file ./gone.png not found" in done.stdout


def test_info_says_which_colour_preview_glass_transmits(tmp_path):
    stage = new_stage(tmp_path / "glass.usda")
    bind(quad(stage, "/World/Clear").GetPrim(), preview_material(stage, "/World/ClearGlass", opacity=0.0))
    bind(quad(stage, "/World/Tinted", z=1).GetPrim(),
         preview_material(stage, "/World/TintedGlass", opacity=0.0, diffuseColor=(0.5, 0.8, 1.0)))
    stage.GetRootLayer().Save()
    done = snell_usd_ok("info", tmp_path / "glass.usda")
    assert "/World/ClearGlass: UsdPreviewSurface, glass (opacity 0, ior 1.5) transmitting (1, 1, 1) (diffuseColor " \
           "unset: clear)" in done.stdout
    assert "/World/TintedGlass: UsdPreviewSurface, glass (opacity 0, ior 1.5) transmitting (0.5, 0.8, 1)," \
           in done.stdout


def test_render_writes_exactly_the_frames_asked(eyes, tmp_path):
    done = snell_usd_ok("render", eyes.usd, "-o", tmp_path / "shot.####.exr", "--frames", "1-9x4,20", "--size", SIZE)
    assert sorted(os.listdir(tmp_path)) == ["shot.0001.exr", "shot.0005.exr", "shot.0009.exr", "shot.0020.exr"]
    assert done.stderr.count("frame ") == 4 and "frame 20 (4/4) -> " in done.stderr
    pixels = read_image(tmp_path / "shot.0009.exr")
    assert pixels.shape == (48, 64, 4) and pixels[..., :3].max() > 0.2


def test_render_writes_a_png_of_the_single_frame(eyes, tmp_path):
    done = snell_usd_ok("render", eyes.usd, "-o", tmp_path / "still.png", "--size", SIZE, "--camera", "/World/Camera")
    assert done.stdout.startswith(f"wrote {tmp_path / 'still.png'}: 64x48, camera /World/Camera, time code 1")
    assert read_image(tmp_path / "still.png").shape == (48, 64, 4)


def test_skip_existing_leaves_finished_frames_alone(eyes, tmp_path):
    (tmp_path / "shot.0002.png").write_bytes(b"finished")
    done = snell_usd("render", eyes.usd, "-o", tmp_path / "shot.####.png", "--frames", "1-3", "--size", SIZE,
                     "--skip-existing")
    assert done.returncode == 0, done.stderr
    assert "skipping 1 of 3 frames: their files exist" in done.stdout
    assert (tmp_path / "shot.0002.png").read_bytes() == b"finished"
    assert sorted(os.listdir(tmp_path)) == ["shot.0001.png", "shot.0002.png", "shot.0003.png"]


def test_quiet_prints_nothing(eyes, tmp_path):
    done = snell_usd("render", eyes.usd, "-o", tmp_path / "s.####.png", "--frames", "1-2", "--size", SIZE, "-q")
    assert done.returncode == 0 and done.stdout == "" and done.stderr == ""


def test_a_stage_with_a_missing_texture_renders_its_fallback_with_a_warning(tmp_path):
    done = snell_usd_ok("render", broken_stage(tmp_path), "-o", tmp_path / "f.png", "--size", SIZE)
    assert "warning: /World/M/Texture_diffuseColor: texture file ./gone.png not found" in done.stderr
    assert (tmp_path / "f.png").is_file()


def test_strict_refuses_a_stage_with_a_missing_texture_and_writes_nothing(tmp_path):
    broken = broken_stage(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    done = snell_usd("render", broken, "-o", out / "f.####.exr", "--frames", "1-3", "--size", SIZE, "--strict")
    assert done.returncode == 1
    assert "/World/M/Texture_diffuseColor: texture file ./gone.png not found" in done.stderr
    assert os.listdir(out) == []


def undecodable_stage(folder) -> object:
    """A card whose texture file is there but is no image: undecodable.usda in `folder`."""
    (folder / "noise.png").write_bytes(b"these bytes are no PNG")
    stage = new_stage(folder / "undecodable.usda")
    card = quad(stage, "/World/Card")
    material = preview_material(stage, "/World/M", diffuseColor=(0.2, 0.9, 0.2))
    texture(stage, material, "./noise.png", fallback=(0.9, 0.1, 0.1, 1.0))
    bind(card.GetPrim(), material)
    stage.GetRootLayer().Save()
    return folder / "undecodable.usda"


def test_a_texture_that_cannot_be_decoded_is_a_warning_naming_the_file_and_its_fallback_is_drawn(tmp_path):
    out = tmp_path / "f.exr"
    done = snell_usd_ok("render", undecodable_stage(tmp_path), "-o", out, "--size", SIZE)
    warning = next((line for line in done.stderr.splitlines() if "/World/M/Texture_diffuseColor" in line), "")
    assert "warning" in warning and str(tmp_path / "noise.png") in warning, done.stderr
    assert "the input's fallback is drawn" in warning, warning
    middle = read_image(out)[24, 32]
    assert middle[0] > 2 * middle[1], f"the fallback's red, not the texture's nor the green factor: {middle}"


def test_strict_refuses_a_texture_that_cannot_be_decoded_and_writes_nothing(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    done = snell_usd("render", undecodable_stage(tmp_path), "-o", out / "f.png", "--size", SIZE, "--strict")
    assert done.returncode == 1, done.stderr
    assert str(tmp_path / "noise.png") in done.stderr and "Traceback" not in done.stderr
    assert os.listdir(out) == []


def empty_stage(folder) -> object:
    """A stage of hair alone, which snell does not draw: empty.usda in `folder`."""
    stage = new_stage(folder / "empty.usda")
    UsdGeom.BasisCurves.Define(stage, "/World/Hair")
    stage.GetRootLayer().Save()
    return folder / "empty.usda"


def test_a_stage_with_nothing_to_draw_renders_its_background_with_a_warning(tmp_path):
    out = tmp_path / "e.exr"
    done = snell_usd_ok("render", empty_stage(tmp_path), "-o", out, "--size", SIZE)
    assert "nothing to draw: no visible UsdGeomMesh or gprim with faces" in done.stderr, done.stderr
    assert "the background is drawn" in done.stderr
    background = [0.02, 0.02, 0.025]  # snell.View's default
    np.testing.assert_allclose(read_image(out)[..., :3], np.broadcast_to(background, (48, 64, 3)),
                               atol=1e-3)


def test_strict_refuses_a_stage_with_nothing_to_draw_and_writes_nothing(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    done = snell_usd("render", empty_stage(tmp_path), "-o", out / "e.png", "--size", SIZE, "--strict")
    assert done.returncode == 1, done.stderr
    assert "nothing to draw" in done.stderr and "Traceback" not in done.stderr
    assert os.listdir(out) == []


def test_a_start_time_code_after_the_end_renders_the_stages_start_frame(tmp_path):
    stage = new_stage(tmp_path / "backwards.usda", time_range=(10, 1))
    quad(stage, "/World/Card")
    stage.GetRootLayer().Save()
    done = snell_usd_ok("render", tmp_path / "backwards.usda", "-o", tmp_path / "f.png", "--size", SIZE)
    assert "time code 10" in done.stdout and (tmp_path / "f.png").is_file()
    assert "startTimeCode 10 is after endTimeCode 1: snell takes the range 1-10" in done.stderr


def test_a_stage_with_a_mesh_without_points_exits_1_and_writes_nothing(tmp_path):
    from pxr import UsdGeom

    stage = new_stage(tmp_path / "broken.usda")
    quad(stage, "/World/Card")
    empty = UsdGeom.Mesh.Define(stage, "/World/Pointless")
    empty.CreateFaceVertexCountsAttr([4])
    empty.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    stage.GetRootLayer().Save()
    out = tmp_path / "out"
    out.mkdir()
    done = snell_usd("render", tmp_path / "broken.usda", "-o", out / "f.png", "--size", SIZE)
    assert done.returncode == 1 and "/World/Pointless: has 1 faces but no points" in done.stderr
    assert os.listdir(out) == []


def test_a_frame_outside_the_time_range_exits_1_and_writes_nothing(eyes, tmp_path):
    done = snell_usd("render", eyes.usd, "-o", tmp_path / "f.####.png", "--frames", "40-50", "--size", SIZE)
    assert done.returncode == 1
    assert "frames 49, 50 are outside the stage's time range 1-48" in done.stderr
    assert os.listdir(tmp_path) == []


def test_a_stage_that_is_not_there_exits_1(tmp_path):
    done = snell_usd("render", tmp_path / "nowhere.usda", "-o", tmp_path / "f.png")
    assert done.returncode == 1 and f"{tmp_path / 'nowhere.usda'}: no such file" in done.stderr
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("args, says", [
    (["--frames", "9-1"], "--frames '9-1': '9-1' runs backwards"),
    (["--frames", "1-3"], "3 frames need a slot for the frame number"),
    (["--size", "big"], "'big' is not WIDTHxHEIGHT"),
    (["--camera", "/World/Nope"], "--camera /World/Nope: "),
])
def test_a_bad_command_line_exits_2(eyes, tmp_path, args, says):
    done = snell_usd("render", eyes.usd, "-o", tmp_path / "f.png", *args)
    assert done.returncode == 2 and says in done.stderr
    assert os.listdir(tmp_path) == []


def test_sigterm_keeps_whole_frames_and_exits_143(eyes, tmp_path):
    process = subprocess.Popen([sys.executable, "-m", "snell.usd", "render", str(eyes.usd), "-o",
                                str(tmp_path / "f.####.exr"), "--frames", "1-48", "--size", "320x240"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = process.stderr.readline()
    while first.startswith("snell-usd: warning: "):  # the rig's sphere lights, drawn as points
        first = process.stderr.readline()
    assert first.startswith("frame 1 (1/48)"), first
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 143, err
    written = sorted(os.listdir(tmp_path))
    assert 1 <= len(written) < 48 and all(name.startswith("f.00") for name in written), written
    for name in written:  # each file is whole: it reads back completely
        assert read_image(tmp_path / name).shape == (240, 320, 4)
    assert "stopped by signal 15" in err


def test_help_lists_the_exit_codes():
    done = snell_usd("render", "--help")
    assert done.returncode == 0 and "exit codes: 0 done, 1 failed" in done.stdout and "--skip-existing" in done.stdout


def test_the_frames_written_are_the_api_s_pictures(eyes, tmp_path, device):
    import snell.usd

    snell_usd("render", eyes.usd, "-o", tmp_path / "f.exr", "--frames", "17", "--size", SIZE, "--float")
    with snell.usd.open(eyes.usd, device=device) as stage:
        stage.set_time(17)
        expected = stage.render(64, 48)
    np.testing.assert_allclose(read_image(tmp_path / "f.exr"), expected, atol=1e-6)


def stage_usd_warns_about(folder) -> object:
    """A card that references a layer that is not there: USD warns while composing it, and draws the card."""
    stage = new_stage(folder / "warns.usda")
    quad(stage, "/World/Card").GetPrim().GetReferences().AddReference("./missing_layer.usda")
    stage.GetRootLayer().Save()
    return folder / "warns.usda"


def test_usds_own_diagnostics_are_snell_usds_warnings_and_not_its_raw_stderr(tmp_path):
    done = snell_usd_ok("render", stage_usd_warns_about(tmp_path), "-o", tmp_path / "f.png", "--size", SIZE)
    said = "USD says: In </World/Card>: Could not open asset @" + str(tmp_path / "missing_layer.usda@")
    assert f"snell-usd: warning: {said}" in done.stderr, done.stderr
    assert "Warning: in " not in done.stderr, "USD printed its diagnostic itself"
    listed = snell_usd("info", tmp_path / "warns.usda")
    assert said in listed.stdout and listed.returncode == 0, listed.stdout
    assert listed.stderr == "", listed.stderr


def test_quiet_silences_usds_own_diagnostics(tmp_path):
    done = snell_usd("-q", "render", stage_usd_warns_about(tmp_path), "-o", tmp_path / "f.png", "--size", SIZE)
    assert done.returncode == 0 and done.stdout == "" and done.stderr == "", done.stderr
    assert (tmp_path / "f.png").is_file()


def test_devices_spreads_the_frames_over_workers_and_writes_one_devices_pixels(eyes, tmp_path):
    """Two workers on one device (as the GPU machine would have two GPUs): the rig's skinning, blend shape
    and camera go with each frame, and every frame's pixels are those the single renderer writes."""
    one = snell_usd("render", eyes.usd, "-o", tmp_path / "one.####.exr", "--frames", "1-41x20", "--size", SIZE,
                    "--float", "--method", "trace")
    two = snell_usd("render", eyes.usd, "-o", tmp_path / "two.####.exr", "--frames", "1-41x20", "--size", SIZE,
                    "--float", "--method", "trace", "--devices", "0,0")
    assert one.returncode == 0 and two.returncode == 0, one.stderr + two.stderr
    assert two.stderr.count("frame ") == 3 and "(3/3)" in two.stderr, two.stderr
    assert "3 frames in" in two.stdout and two.stdout.count("llvmpipe") == 2, two.stdout  # both workers listed
    for frame in (1, 21, 41):
        single, shot = read_image(tmp_path / f"one.{frame:04d}.exr"), read_image(tmp_path / f"two.{frame:04d}.exr")
        np.testing.assert_allclose(shot, single, atol=2e-3, err_msg=f"frame {frame}")
    assert not np.allclose(read_image(tmp_path / "two.0001.exr"), read_image(tmp_path / "two.0021.exr"))


def test_devices_takes_snell_renders_lists_and_refuses_a_bad_one(eyes, tmp_path):
    done = snell_usd("render", eyes.usd, "-o", tmp_path / "f.png", "--devices", "0,,1")
    assert done.returncode == 2 and "--devices 0,,1: give all, or device indices" in done.stderr, done.stderr
    assert os.listdir(tmp_path) == []
