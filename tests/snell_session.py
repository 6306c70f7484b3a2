"""The session's device, shared by the Python suites (tests/python and tests/usd).

Each suite's conftest puts this folder on the path and imports `device` from
here, which is how pytest finds the fixture.
"""

from __future__ import annotations

import os

import pytest

import snell

VALIDATION = os.environ.get("SNELL_VALIDATION") == "1"


@pytest.fixture(scope="session")
def device():
    """A device with validation on where CI asks for it; a validation message fails the test."""
    with snell.Device(validation=VALIDATION) as d:
        yield d
        assert d.validation_messages == 0, "the Khronos validation layer reported messages (see standard error)"
