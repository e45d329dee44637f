"""stirling: energetic, symbolic modeling of free-piston Stirling engines, from Python.

The Rust library behind the ``stirling`` command line, as Python objects::

    import stirling

    m = stirling.load("schmidt")                 # the seed's 4th-order model
    lin = m.linearize()                          # poles, margins, Bode, state space
    print(lin.margins)                           # Gm -6.63 dB at 81.6 rad/s, ...
    sys = lin.broken_loop.to_control()           # a control.StateSpace (python-control)

    m8 = stirling.load("order8")                 # nsection with 2 regenerator sections
    lc = m8.limit_cycle()                        # frequency, strokes, work, power, Floquet
    rec = stirling.rig("order8", effects={"leak": 2e-8}, settle=3, t_end=1.5)
    fit = m8.fit(rec)                            # the two-stage fit with intervals
    d = m8.diagnose(rec)                         # which omitted effect, how far it closes

Long work releases the GIL, reports progress (``progress=True``: a tqdm bar) and stops on
Ctrl-C. Errors are :mod:`stirling.errors` classes with the library's messages. The guide is
docs/python.md in the repository.
"""

from __future__ import annotations

from . import errors, results
from ._model import EffectInfo, Model, ModelInfo, Parameter, State, effects, load, models
from ._native import __version__
from ._record import Record, RigRecord, read_csv, rig
from .errors import (
    DiagnosisError,
    FitError,
    InternalError,
    LinearizationError,
    ModelError,
    OptionError,
    ParameterError,
    RecordError,
    SimulationError,
    StirlingError,
)

__all__ = [
    "__version__",
    "load",
    "models",
    "effects",
    "rig",
    "read_csv",
    "Model",
    "ModelInfo",
    "Parameter",
    "State",
    "EffectInfo",
    "Record",
    "RigRecord",
    "errors",
    "results",
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
