"""Progress reporting for long work: a callback, a tqdm bar, or nothing.

The native code calls ``callback(done, total, line)`` from the calling thread a few times a
second: ``done`` out of ``total`` in the work's unit (simulated seconds, sweep points; ``total``
is 0 when the work has no known size) and ``line``, a line of text or ``None``.
"""

from __future__ import annotations

import math
import sys
from typing import Callable, Optional, Union

ProgressCallback = Callable[[float, float, Optional[str]], None]
Progress = Union[None, bool, ProgressCallback]

__all__ = ["Progress", "ProgressCallback", "reporter"]


class _Bar:
    """A tqdm bar (when tqdm is installed) or plain lines on stderr, opened at the first call."""

    def __init__(self, desc: str, unit: str) -> None:
        self.desc, self.unit = desc, unit
        self.bar = None  # the tqdm bar, when tqdm is installed and the total is known
        self.opened = False
        self.shown = -1

    def __call__(self, done: float, total: float, line: Optional[str]) -> None:
        if not self.opened:
            self.opened = True
            self.bar = self._open(total)
        if line is not None:
            self._write(line)
        if not math.isnan(done):
            self._move(done, total)

    def _open(self, total: float):
        if not total > 0:
            return None  # work of unknown size reports lines only
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return None
        return tqdm(total=total, desc=self.desc, unit=self.unit, leave=False)

    def _write(self, line: str) -> None:
        if self.bar is not None:
            self.bar.write(line)
        else:
            print(line, file=sys.stderr)

    def _move(self, done: float, total: float) -> None:
        if self.bar is not None:
            self.bar.n = round(done, 6)
            self.bar.refresh()
        elif total > 0:
            tenth = int(10 * done / total)
            if tenth > self.shown:
                self.shown = tenth
                print(f"{self.desc}: {10 * tenth} %", file=sys.stderr)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def reporter(progress: Progress, desc: str, unit: str = "s"):
    """The callback for the native code and a function that closes it (a context manager)."""
    if progress is None or progress is False:
        return _Closing(None)
    if progress is True:
        return _Closing(_Bar(desc, unit))
    if callable(progress):
        return _Closing(progress)
    from .errors import OptionError

    raise OptionError(f"progress must be None, True or a callable (done, total, line), got {progress!r}")


class _Closing:
    def __init__(self, callback) -> None:
        self.callback = callback

    def __enter__(self):
        return self.callback

    def __exit__(self, *exc) -> None:
        close = getattr(self.callback, "close", None)
        if isinstance(self.callback, _Bar) and close is not None:
            close()
