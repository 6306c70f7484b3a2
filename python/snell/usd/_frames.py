"""Frame lists and file names as `snell render` reads them (src/farm/frames.cpp, the same rules).

A list is items separated by commas, each a frame or a range:
first:last[:step] (snell's own), first-last[xstep] (Deadline, Nuke),
first-last:step (Open Job Description). Frames are 0 or more, increasing,
each once. A file name holds the frame number as '#'s (shot.####.exr:
shot.0042.exr) or a printf %d / %0Nd.
"""

from __future__ import annotations

import re


class UsageError(Exception):
    """A bad command line: the message names the option."""


def _number(option: str, quoted: str, text: str) -> int:
    if not re.fullmatch(r"-?\d+", text):
        raise UsageError(f"{option} {quoted}: '{text}' is not a whole number")
    value = int(text)
    if value < 0:
        raise UsageError(f"{option} {quoted}: frame numbers are 0 or more, got {text}")
    return value


def _item(option: str, quoted: str, spaced: str) -> list[int]:
    text = spaced.replace(" ", "")  # Open Job Description writes "1 - 10"
    step = 1
    colon, dash = text.find(":"), text.find("-")
    if dash != -1 and colon != -1 and dash < colon:
        first = _number(option, quoted, text[:dash])
        last = _number(option, quoted, text[dash + 1:colon])
        step = _number(option, quoted, text[colon + 1:])
    elif colon != -1:
        second = text.find(":", colon + 1)
        first = _number(option, quoted, text[:colon])
        last = _number(option, quoted, text[colon + 1:] if second == -1 else text[colon + 1:second])
        if second != -1:
            step = _number(option, quoted, text[second + 1:])
    elif dash != -1:
        x = text.find("x", dash)
        first = _number(option, quoted, text[:dash])
        last = _number(option, quoted, text[dash + 1:] if x == -1 else text[dash + 1:x])
        if x != -1:
            step = _number(option, quoted, text[x + 1:])
    else:
        first = last = _number(option, quoted, text)
    if step <= 0:
        raise UsageError(f"{option} {quoted}: the step of '{text}' must be 1 or more")
    if last < first:
        raise UsageError(f"{option} {quoted}: '{text}' runs backwards: it ends at {last}, before it starts at {first}")
    return list(range(first, last + 1, step))


def parse_frames(option: str, text: str) -> list[int]:
    """The frames of a list, increasing; UsageError names the option and the list."""
    if not text:
        raise UsageError(f"{option}: give frames, e.g. 1-240, 1:240:4 or 1,5,10-20")
    quoted = f"'{text}'"
    frames: list[int] = []
    spans: list[tuple[int, int]] = []
    for part in text.split(","):
        if not part:
            raise UsageError(f"{option} {quoted}: an empty item between commas")
        items = _item(option, quoted, part)
        for lo, hi in spans:
            if items[0] <= hi and items[-1] >= lo:
                raise UsageError(f"{option} {quoted}: '{part}' overlaps frames {lo}-{hi} listed before it")
        spans.append((items[0], items[-1]))
        frames += items
    return sorted(frames)


def has_frame_slot(pattern: str) -> bool:
    """Whether a file name has a slot for the frame number: '#'s or a printf %d / %0Nd."""
    return "#" in pattern or re.search(r"%\d*d", pattern) is not None


def frame_path(pattern: str, frame: int) -> str:
    """The file name of a frame: '#'s become the number zero-padded to their count, %d or %0Nd as printf."""
    hashes = re.search(r"#+", pattern)
    if hashes:
        return pattern[:hashes.start()] + str(frame).zfill(len(hashes.group())) + pattern[hashes.end():]
    printf = re.search(r"%(\d*)d", pattern)
    if printf:
        width = printf.group(1)
        digits = str(frame)
        if width:
            digits = digits.rjust(int(width), "0" if width.startswith("0") else " ")
        return pattern[:printf.start()] + digits + pattern[printf.end():]
    return pattern


def check_frame_pattern(option: str, pattern: str, frames: int) -> None:
    """Several frames need a slot in the name; a single one may have none."""
    if frames > 1 and not has_frame_slot(pattern):
        raise UsageError(f"{option} {pattern}: {frames} frames need a slot for the frame number in the name, '#'s or "
                         "%04d (e.g. shot.####.exr)")
