"""The exceptions stirling raises, each with the library's message (what is wrong and where).

Every class derives from :class:`StirlingError`. A wrong input raises a class that is also a
:class:`ValueError`, so ``except ValueError`` catches it as it would in numpy or SciPy; an
analysis that fails on a valid input raises a class that is also a :class:`RuntimeError`.

Messages come from the library the command line uses, so they sometimes name its options
(``--set``, ``--t-end``): the keyword arguments of the Python functions carry the same names
with underscores (``params``, ``t_end``).
"""

from __future__ import annotations

__all__ = [
    "StirlingError",
    "ModelError",
    "ParameterError",
    "RecordError",
    "OptionError",
    "SimulationError",
    "LinearizationError",
    "FitError",
    "DiagnosisError",
    "InternalError",
]


class StirlingError(Exception):
    """Base of every error raised by stirling."""


class ModelError(StirlingError, ValueError):
    """An unknown model, alias or closure, or a section count that does not apply."""


class ParameterError(StirlingError, ValueError):
    """An unknown parameter name, a value that is not a number or not physical, bad bounds."""


class RecordError(StirlingError, ValueError):
    """A measured record that cannot be read or used: shapes, non-finite values, time not
    increasing, irregular sampling, a missing channel, too short, or without motion."""


class OptionError(StirlingError, ValueError):
    """A wrong argument: an array of the wrong shape or with a non-finite entry, a tolerance
    or time out of range, an unknown effect, channel or route."""


class SimulationError(StirlingError, RuntimeError):
    """A run that failed: a nonphysical state, a collapsed step, no periodic motion, shooting
    that did not converge."""


class LinearizationError(StirlingError, RuntimeError):
    """The equilibrium or the poles could not be computed."""


class FitError(StirlingError, RuntimeError):
    """An identification that failed on a usable record."""


class DiagnosisError(StirlingError, RuntimeError):
    """A diagnosis that failed on a usable record."""


class InternalError(StirlingError, RuntimeError):
    """A defect of stirling itself (please report it with the message)."""
