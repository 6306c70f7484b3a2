"""The rigged eye pair read from USD renders as the same scene loaded from glTF."""

from __future__ import annotations

import numpy as np
import pytest

import snell
import snell.usd
from conftest import srgb8, unexpected
from eye_stage import TIME_CODES_PER_SECOND

WIDTH, HEIGHT = 160, 120
TIMES = (1.0, 20.0, 37.5)  # a key, and two time codes between keys (slerped gaze, interpolated pupil)


@pytest.fixture(scope="module")
def pictures(device, eyes):
    """(USD picture, glTF picture) in 8-bit sRGB at each time code of TIMES."""
    gltf = snell.Renderer(device, snell.Scene.load(str(eyes.gltf)))
    out = {}
    with snell.usd.open(eyes.usd, device=device) as stage:
        assert not unexpected(stage.warnings), unexpected(stage.warnings)
        for t in TIMES:
            stage.set_time(t)
            gltf.set_time(t / TIME_CODES_PER_SECOND)
            out[t] = srgb8(stage.render(WIDTH, HEIGHT)), srgb8(gltf.render(snell.View(WIDTH, HEIGHT, camera=0)))
    gltf.close()
    return out


@pytest.mark.parametrize("t", TIMES)
def test_eye_rig_renders_as_its_gltf_twin(pictures, t):
    """The USD stage (UsdSkel gaze and pupil blend shape, faceVarying normals, cornea GeomSubset of glass,
    iris texture through an interface-connected primvar reader, preview-purpose materials, sphere, distant
    and spot lights, camera) and its glTF twin differ by at most 1/255 in 8-bit sRGB on 99% of the pixels
    or more, at a key and between keys."""
    usd, gltf = pictures[t]
    differ = np.abs(usd - gltf).max(axis=2) > 1
    assert differ.mean() <= 0.01, f"at time code {t}, {differ.sum()} pixels differ by more than 1/255"


def test_eye_rig_moves_between_time_codes(pictures):
    """The gaze and pupil really move: pictures at different time codes differ (else the twin test proves little)."""
    first, later = pictures[TIMES[0]][0], pictures[TIMES[1]][0]
    assert (np.abs(first - later).max(axis=2) > 8).mean() > 0.01


def test_eye_rig_shows_the_preview_materials(pictures):
    """The full-purpose sclera is red and the all-purpose iris green: neither may show."""
    usd = pictures[TIMES[0]][0]
    red = (usd[..., 0] > 150) & (usd[..., 1] < 90) & (usd[..., 2] < 90)
    green = (usd[..., 1] > 150) & (usd[..., 0] < 90) & (usd[..., 2] < 90)
    assert red.sum() == 0 and green.sum() == 0
    sclera = (usd[..., 0] > 170) & (usd[..., 1] > 160) & (usd[..., 2] > 150)
    assert sclera.mean() > 0.05, "the preview sclera (off-white) is missing"


def test_eye_rig_feeds_only_its_deforming_meshes(device, eyes):
    """Per frame the four skinned meshes' six parts are re-sent and nothing else; the lights stay."""
    with snell.usd.open(eyes.usd, device=device) as stage:
        stage.render(WIDTH, HEIGHT)
        feed = stage.set_time(9.0)
        stage.render(WIDTH, HEIGHT)
        frame = stage.renderer.last_frame()
    assert feed.meshes == 6 and feed.transforms == 0
    assert frame["meshes_uploaded"] == 6 and frame["trees_refit"] + frame["trees_built"] == 6
