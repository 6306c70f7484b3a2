"""snell-usd's frame lists and file names follow `snell render`'s (src/farm/frames.cpp)."""

from __future__ import annotations

import pytest

from snell.usd._frames import UsageError, check_frame_pattern, frame_path, parse_frames


@pytest.mark.parametrize("text, frames", [
    ("1001-1005", [1001, 1002, 1003, 1004, 1005]),
    ("1-9x4", [1, 5, 9]),
    ("1:9:4", [1, 5, 9]),
    ("1-9:4", [1, 5, 9]),
    ("1 - 3", [1, 2, 3]),
    ("10-12,1,5", [1, 5, 10, 11, 12]),
    ("7", [7]),
])
def test_frame_lists_read_as_snell_render_reads_them(text, frames):
    assert parse_frames("--frames", text) == frames


@pytest.mark.parametrize("text, says", [
    ("", "--frames: give frames, e.g. 1-240"),
    ("5-1", "'5-1' runs backwards: it ends at 1, before it starts at 5"),
    ("1-9x0", "the step of '1-9x0' must be 1 or more"),
    ("1-5,3", "'3' overlaps frames 1-5 listed before it"),
    ("1,,2", "an empty item between commas"),
    ("a-3", "'a' is not a whole number"),
    ("-3", "'' is not a whole number"),
])
def test_a_bad_frame_list_is_a_usage_error_naming_the_list(text, says):
    with pytest.raises(UsageError, match=says.replace("(", r"\(")):
        parse_frames("--frames", text)


@pytest.mark.parametrize("pattern, path", [
    ("shot.####.exr", "shot.0042.exr"),
    ("shot.#.exr", "shot.42.exr"),
    ("shot.%04d.png", "shot.0042.png"),
    ("shot.%d.png", "shot.42.png"),
    ("shot.%5d.png", "shot.   42.png"),
    ("still.png", "still.png"),
])
def test_frame_numbers_fill_the_names_slot(pattern, path):
    assert frame_path(pattern, 42) == path


def test_several_frames_need_a_slot_in_the_name():
    check_frame_pattern("-o", "one.png", 1)
    with pytest.raises(UsageError, match="-o many.png: 2 frames need a slot"):
        check_frame_pattern("-o", "many.png", 2)
