"""What goes wrong while reading a stage: warnings that name the prim, and errors.

A warning says what snell leaves out or approximates (an unsupported shader,
a wrap mode snell cannot draw, a missing texture drawn with its fallback as
usdview draws it; strict readers raise that one). An error says the stage is broken where snell
needs it (a texture file that cannot be decoded, a mesh whose faces have no
points): strict readers raise it at once, others keep it as a warning marked
as an error, which `snell-usd render` refuses.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from typing import Iterator, Optional

from pxr import Tf

from .. import Error


class StageError(Error):
    """A stage snell cannot read or draw as asked; the message names the file, the prim and the problem."""


@dataclass(frozen=True)
class StageWarning:
    """One thing snell could not read as the stage says."""

    prim: str  #: the prim's path, '' for the stage as a whole
    message: str
    error: bool = False  #: the stage is broken here (strict readers raise StageError instead)

    def __str__(self) -> str:
        text = f"{self.prim}: {self.message}" if self.prim else self.message
        return f"error: {text}" if self.error else text


class Problems:
    """The warnings of one stage, each said once, in the order found."""

    def __init__(self, stage_path: str, strict: bool, strict_missing: Optional[bool] = None) -> None:
        self.stage_path = stage_path
        self.strict = strict
        self.strict_missing = strict if strict_missing is None else strict_missing
        self.items: list[StageWarning] = []
        self._seen: set[tuple[str, str]] = set()

    def warn(self, prim: object, message: str) -> None:
        self._add(StageWarning(str(prim) if prim else "", message))

    def fail(self, prim: object, message: str) -> None:
        """A broken stage: raised when strict, else kept as an error-marked warning."""
        item = StageWarning(str(prim) if prim else "", message, error=True)
        if self.strict:
            where = f"{item.prim}: " if item.prim else ""
            raise StageError(f"{self.stage_path}: {where}{message}")
        self._add(item)

    def strict_error(self, prim: object, message: str) -> None:
        """What snell draws around (a missing texture, with the input's fallback): an error where missing files
        are (strict), else a plain warning."""
        if self.strict_missing:
            self.fail(prim, message)
        else:
            self.warn(prim, message)

    def _add(self, item: StageWarning) -> None:
        key = (item.prim, item.message)
        if key not in self._seen:
            self._seen.add(key)
            self.items.append(item)

    @property
    def errors(self) -> list[StageWarning]:
        return [w for w in self.items if w.error]

    @contextlib.contextmanager
    def usd_diagnostics(self) -> Iterator[None]:
        """USD's own warnings, statuses and posted errors while the block runs (what it would print on standard
        error: a reference to a missing layer, a value of the wrong type), kept as this stage's warnings ('USD
        says: ...') instead, so they go where snell's warnings go (snell-usd prints them; -q silences them).
        Errors USD raises (Tf.ErrorException) pass through as they are. A usd-core without Tf.DiagnosticTrap
        leaves them on standard error."""
        trap_type = getattr(Tf, "DiagnosticTrap", None)
        if trap_type is None:
            yield
            return
        with trap_type() as trap:
            try:
                yield
            finally:
                said = list(trap.GetErrors()) + list(trap.GetWarnings()) + list(trap.GetStatuses())
                trap.Clear()
                for diagnostic in said:
                    text = " ".join(str(diagnostic.commentary).split())
                    if "Cannot determine file format" in text and ".mtlx" in text:
                        continue  # usd-core has no MaterialX plugin: snell reads the document itself (_mtlx.py)
                    if text:
                        self.warn("", f"USD says: {text}")
