"""Models by name and their analyses."""

from __future__ import annotations

import os
import warnings
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._progress import Progress, reporter
from ._record import Record, RigRecord, _as_native, _block, rig
from .errors import ModelError, OptionError
from .results import (
    Diagnosis,
    Equilibrium,
    Fields,
    Fit,
    LimitCycle,
    Linearization,
    Poles,
    Simulation,
    Sweep,
)

__all__ = ["Model", "ModelInfo", "Parameter", "State", "EffectInfo", "load", "models", "effects"]


class ModelInfo(NamedTuple):
    """A model :func:`load` knows: its name, aliases and a one-line summary."""

    name: str
    aliases: Tuple[str, ...]
    summary: str
    registered: bool


class Parameter(NamedTuple):
    """A model parameter: its current ``value`` and ``default`` (in ``unit``), what it is
    (``doc``) and the range a fit keeps it in (``bounds``, ``None``: the fit's default)."""

    name: str
    value: float
    default: float
    unit: str
    doc: str
    bounds: Optional[Tuple[float, float]]


class State(NamedTuple):
    """A state: name, kind (``position``, ``velocity``, ``pressure``, ``mass``,
    ``wall_temperature``), index of its body or vessel, unit and meaning."""

    name: str
    kind: str
    index: int
    unit: str
    meaning: str


class EffectInfo(NamedTuple):
    """An effect of the library: what it does, its parameters (the strength first) with
    their null and typical values, and the models whose augmented member carries it."""

    name: str
    summary: str
    params: Tuple[Dict[str, Any], ...]
    applies_to: Tuple[str, ...]


def models() -> List[ModelInfo]:
    """The models :func:`load` knows: the family (``schmidt``, ``cv1``, ``cv2``, ``nsection``,
    aliases ``order4`` .. ``order8``) and the engines registered from Rust."""
    return [ModelInfo(d["name"], tuple(d["aliases"]), d["summary"], d["registered"]) for d in _native.models()]


def effects() -> List[EffectInfo]:
    """The effects the rig can switch on and the diagnosis can name."""
    return [EffectInfo(d["name"], d["summary"], tuple(d["params"]), tuple(d["applies_to"])) for d in _native.effects()]


def load(
    name_or_path: Union[str, "os.PathLike[str]"],
    n: Optional[int] = None,
    closure: str = "full",
    params: Optional[Mapping[str, float]] = None,
) -> "Model":
    """A model by name: ``schmidt`` (the seed's 4th-order model), ``cv1``, ``cv2``,
    ``nsection`` with ``n`` regenerator sections (default 1), an alias ``order4`` ..
    ``order8`` (``order8`` is ``nsection`` with n = 2), or a registered engine.

    ``closure`` is ``"full"`` (mass states, the default) or ``"frozen"`` (the seed's order
    count); ``params`` sets parameters by name over the defaults (checked: an unknown name or a
    value that is not physical raises :class:`~stirling.errors.ParameterError`).

    A path ending in ``.stirling`` loads an engine declared in a file (docs/custom-topologies.md):
    read, checked and compiled at run time; a mistake raises :class:`~stirling.errors.ModelError`
    with its ``file:line:column``.
    """
    name = os.fspath(name_or_path)
    if not isinstance(name, str):
        raise ModelError(f"a model is named by a string, got {name_or_path!r}")
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1):
        raise ModelError(f"n must be a whole number of sections >= 1, got {n!r}")
    if closure not in ("full", "frozen"):
        raise ModelError(f"unknown closure {closure!r}: expected 'full' or 'frozen'")
    native = _native.NativeModel(name, None if n is None else int(n), closure)
    return Model._make(native, native.params(None if params is None else dict(params)))


def _time(v: float, name: str) -> float:
    try:
        f = float(v)
    except (TypeError, ValueError):
        raise OptionError(f"{name} must be a number of seconds, got {v!r}") from None
    return f


class Model:
    """A model with its parameter values.

    Load one with :func:`load`; it is immutable: :meth:`with_params` gives a copy with other
    values. Every analysis runs at the model's parameters.
    """

    __slots__ = ("_m", "_p", "_states", "_names")

    @classmethod
    def _make(cls, native: "_native.NativeModel", p: np.ndarray) -> "Model":
        self = cls.__new__(cls)
        self._m = native
        self._p = p
        self._p.setflags(write=False)
        self._states = [State(**s) for s in native.states()]
        self._names = [s.name for s in self._states]
        return self

    # ------------------------------------------------------------------------ what it is

    @property
    def name(self) -> str:
        """The model's declared name (``nsection`` for ``order8``)."""
        return self._m.name

    @property
    def n(self) -> int:
        """Regenerator sections (1 for a model without an array)."""
        return self._m.n

    @property
    def closure(self) -> str:
        return self._m.closure

    @property
    def n_states(self) -> int:
        return self._m.n_states

    @property
    def states(self) -> List[State]:
        """The states in order, with kind, unit and meaning."""
        return list(self._states)

    @property
    def state_names(self) -> List[str]:
        return list(self._names)

    @property
    def bodies(self) -> List[Dict[str, str]]:
        """The bodies: name, position state, velocity state."""
        return self._m.bodies()

    @property
    def vessels(self) -> List[str]:
        """The gas vessels (control volumes, then spaces)."""
        return self._m.vessel_names()

    @property
    def sensors(self) -> List[Dict[str, Any]]:
        """The sensors the model declares (name, what it reads, unit)."""
        return self._m.sensors()

    @property
    def effect_sites(self) -> List[Dict[str, Any]]:
        """The effects the model names where they act (tested by the diagnosis)."""
        return self._m.effect_sites()

    @property
    def parameters(self) -> Dict[str, Parameter]:
        """Every parameter: value, default, unit, doc and declared bounds."""
        return {
            d["name"]: Parameter(d["name"], float(v), d["default"], d["unit"], d["doc"], d["bounds"])
            for d, v in zip(self._m.parameters(), self._p)
        }

    @property
    def params(self) -> Dict[str, float]:
        """The parameter values by name."""
        return {d["name"]: float(v) for d, v in zip(self._m.parameters(), self._p)}

    @property
    def param_vector(self) -> np.ndarray:
        """The parameter values in the model's order (read-only)."""
        return self._p

    def with_params(self, values: Optional[Mapping[str, float]] = None, **kw: float) -> "Model":
        """A copy with parameters set by name (over this model's values), checked."""
        d = dict(values or {})
        d.update(kw)
        return Model._make(self._m, self._m.params(d, self._p))

    def equations(self, style: str = "text") -> str:
        """The generated equations, ``"text"`` or ``"latex"``."""
        return self._m.equations(style)

    def dot(self) -> str:
        """The bond graph as Graphviz DOT: 0- and 1-junctions, causal strokes, half-arrows
        (as ``stirling info --graph`` writes it; docs/bond-graphs.md)."""
        return self._m.dot()

    def bond_svg(self) -> str:
        """The bond graph drawn as SVG, no Graphviz needed (``stirling info --graph --svg``)."""
        return self._m.bond_svg()

    # ------------------------------------------------------------------ the equations

    def rhs(self, x: Any, t: float = 0.0) -> np.ndarray:
        """``f(x, p, t)``: the time derivative of every state at ``x``."""
        return self._m.rhs(self._p, x, t)

    def jacobian(self, x: Any, t: float = 0.0) -> np.ndarray:
        """The analytic Jacobian ``df/dx`` (n_states x n_states)."""
        return self._m.jacobian(self._p, x, t)

    def rhs_and_jacobian(self, x: Any, t: float = 0.0) -> Tuple[np.ndarray, np.ndarray]:
        """``f`` and ``df/dx`` in one call (sharing their common values)."""
        return self._m.rhs_and_jacobian(self._p, x, t)

    def param_jacobian(self, x: Any, t: float = 0.0) -> np.ndarray:
        """The analytic ``df/dp`` (n_states x parameters, in :attr:`params` order)."""
        return self._m.param_jacobian(self._p, x, t)

    def pv(self, x: Any) -> Dict[str, Tuple[float, float]]:
        """Each vessel's ``(pressure (Pa), volume (m^3))`` at ``x``."""
        p, v = self._m.pv(self._p, x)
        return {name: (float(a), float(b)) for name, a, b in zip(self._m.vessel_names(), p, v)}

    def energy(self, x: Any) -> Dict[str, float]:
        """Stored ``energy`` (J), ``gas_mass`` (kg) and the rates ``heat``, ``boundary``,
        ``mechanical`` (W) at ``x``."""
        return self._m.energy(self._p, x)

    def rest_state(self, perturb: float = 0.0) -> np.ndarray:
        """The closed-form rest state (docs/physics.md section 6) with the displacer moved by
        ``perturb`` (m): the start of :meth:`simulate` without ``x0``."""
        return _native.initial_state(self._m, self._p, perturb)

    # ------------------------------------------------------------------- linear analysis

    def equilibrium(self) -> Equilibrium:
        """The rest state by Newton on the analytic Jacobian."""
        return Equilibrium(_native.equilibrium(self._m, self._p), self._names)

    def poles(self, which: Union[str, int] = "auto") -> Poles:
        """The dynamic poles at rest (1/s): ``"auto"`` (all up to 400 states, else the
        dominant ones), ``"all"``, or a count of dominant poles."""
        return Poles(_native.poles(self._m, self._p, which), self._names)

    def linearize(self, channel: Optional[str] = None, poles: Union[str, int] = "auto") -> Linearization:
        """Linearize at rest and break the loop at a pressure force: ``channel`` is
        ``"pressure"`` (single-pressure models) or a body (``piston``, ``displacer``); default
        pressure where there is one, else the piston. The result holds the poles, the margins,
        Bode and Nyquist data and the broken and closed loops as state space."""
        return Linearization(_native.linearize(self._m, self._p, channel, poles))

    # -------------------------------------------------------------------------- running

    def _start(self, x0: Any, perturb: Optional[float]) -> Any:
        if x0 is not None and perturb is not None:
            raise OptionError("give x0 or perturb, not both")
        if x0 is not None:
            return x0
        return self.rest_state(5e-3 if perturb is None else perturb)

    def simulate(
        self,
        t_end: float,
        x0: Any = None,
        perturb: Optional[float] = None,
        samples: int = 2000,
        rtol: float = 1e-7,
        atol: Optional[float] = None,
        progress: Progress = None,
    ) -> Simulation:
        """Simulate from ``x0`` (default: rest with the displacer displaced by ``perturb``,
        5e-3 m) to ``t_end`` (s), sampled at ``samples`` rows (the first at 0, the last at
        ``t_end``), BDF with relative tolerance ``rtol`` and scaled absolute tolerance ``atol``
        (default ``rtol``). A nonphysical state stops the run with
        :class:`~stirling.errors.SimulationError`. Ctrl-C stops it too.

        ``progress``: ``True`` for a bar (tqdm when installed), or a callable
        ``(t, t_end, line)``.
        """
        t_end = _time(t_end, "t_end")
        start = self._start(x0, perturb)
        with reporter(progress, "simulating", "s") as cb:
            raw = _native.simulate(self._m, self._p, start, t_end, _count(samples), rtol, rtol if atol is None else atol, cb)
        return Simulation(raw, self._names)

    def limit_cycle(
        self,
        t_max: float = 20.0,
        x0: Any = None,
        perturb: Optional[float] = None,
        samples: int = 2000,
        rtol: float = 1e-7,
        atol: Optional[float] = None,
        shooting: str = "auto",
        progress: Progress = None,
    ) -> LimitCycle:
        """Run until the motion repeats (at most ``t_max`` s), refine the periodic orbit by
        shooting and measure it: frequency, strokes, phase, pressure amplitudes, Floquet
        multipliers, work per cycle and power. ``shooting``: ``"auto"`` (dense monodromy up to
        400 states, the block route with the leading multipliers above), ``"dense"``,
        ``"block"``, ``"krylov"`` or ``"none"``. The other arguments as :meth:`simulate`."""
        t_max = _time(t_max, "t_max")
        start = self._start(x0, perturb)
        with reporter(progress, "settling", "s") as cb:
            raw = _native.limit_cycle(self._m, self._p, start, t_max, _count(samples), rtol, rtol if atol is None else atol, shooting, cb)
        return LimitCycle(raw, self._names)

    # -------------------------------------------------------------- records, fit, diagnosis

    def _rig_name(self) -> Tuple[str, Optional[int]]:
        return self._m.requested, (self.n if self._m.has_array else None)

    def _changed(self) -> Dict[str, float]:
        return {d["name"]: float(v) for d, v in zip(self._m.parameters(), self._p) if v != d["default"]}

    def rig(self, **kw: Any) -> RigRecord:
        """The virtual rig on this model (its name, sections and parameters as the truth's);
        the keyword arguments as :func:`stirling.rig`."""
        name, n = self._rig_name()
        params = self._changed()
        params.update(kw.pop("params", None) or {})
        return rig(name, n=n, params=params, **kw)

    def fit(
        self,
        record: Union[Record, Any],
        free: Optional[Sequence[str]] = None,
        bounds: Optional[Mapping[str, Tuple[float, float]]] = None,
        train: Optional[Tuple[float, float]] = None,
        holdout: Optional[Tuple[float, float]] = None,
        multiple_shooting: Optional[float] = None,
        restart_cycles: Optional[float] = None,
    ) -> Fit:
        """The two-stage identification from this model's parameters: stage 1 fits the
        mechanics driven by the measured pressure, stage 2 the gas driven by the measured
        positions; then the free run validates on the held-out block.

        ``free``: the parameters fitted (default: those the model declares free, else
        ``kd, kp, bd, bp, hh, hk, Rf`` where used); ``bounds``: ``{name: (lo, hi)}`` over the
        declared ones; ``train``/``holdout``: blocks ``(start, end)`` in s (default: the first
        70 % and the rest); ``multiple_shooting``: refine over segments of that many cycles;
        ``restart_cycles``: restart stage 1 from the measured body states every that many
        cycles (a piston between end stops, which one driven run cannot follow).
        A stage that does not converge warns (:attr:`Fit.converged`).
        """
        raw = _native.fit(
            self._m, self._p, _as_native(record), None if free is None else list(free),
            None if bounds is None else dict(bounds), _block(train, "train"), _block(holdout, "holdout"),
            multiple_shooting, restart_cycles,
        )
        res = Fit(raw)
        for s in res.stages:
            if not s.converged:
                warnings.warn(
                    f"{s.name} did not converge in {s.raw['iterations']} iterations: the estimates are not an optimum "
                    "(a longer record, more excitation or better starting values may help)",
                    RuntimeWarning,
                    stacklevel=2,
                )
        return res

    def diagnose(
        self,
        record: Union[Record, Any],
        effects: Optional[Sequence[str]] = None,
        bounds: Optional[Mapping[str, Tuple[float, float]]] = None,
        train: Optional[Tuple[float, float]] = None,
        holdout: Optional[Tuple[float, float]] = None,
        prior: float = 0.5,
        fit_all: bool = False,
        progress: Progress = None,
    ) -> Diagnosis:
        """The sim-to-real gap diagnosis of ``record`` against this model's augmented member
        (``cv1``, ``nsection``, ``nsection_ext`` or a registered engine with effect sites),
        starting from this model's parameters: the nominal calibration, where the gap lies,
        which omitted effects explain it and how far they close it, with intervals.

        ``effects``: the candidates (default: every one that applies); ``prior``: the spread
        of the prior on the nominal parameters as a log standard deviation (0: none);
        ``train``/``holdout`` as :meth:`fit` (default 60 %); ``fit_all`` fits every candidate.
        ``progress``: ``True`` prints the diagnosis's progress lines (or a callable).
        """
        name, n = self._rig_name()
        with reporter(progress, "diagnosing", "") as cb:
            raw = _native.diagnose(
                name, _as_native(record), n, self._changed(), None if effects is None else list(effects),
                None if bounds is None else dict(bounds), _block(train, "train"), _block(holdout, "holdout"),
                float(prior), bool(fit_all), cb,
            )
        return Diagnosis(raw)

    # ----------------------------------------------------------------------------- sweeps

    def sweep(
        self,
        grid: Mapping[str, Any],
        ties: Optional[Mapping[str, str]] = None,
        untie: bool = False,
        settle: Optional[float] = 10.0,
        progress: Progress = None,
    ) -> Sweep:
        """A design sweep over ``grid``: ``{name: values}``, each axis a sequence of values or
        ``(start, stop, count)`` as a ``tuple``; the grid is the product, the last axis varying
        fastest. ``ties``: ``{follower: leader}`` keeps the follower's ratio to its leader
        (``Pb`` follows a swept ``Pmean`` unless ``untie``). ``settle`` (s) bounds each limit
        cycle's settling; ``None`` computes the poles only. The points run on every core."""
        axes = [(str(k), _axis(k, v)) for k, v in grid.items()]
        tie_list = [(str(f), str(l)) for f, l in (ties or {}).items()]
        with reporter(progress, "sweep", "points") as cb:
            raw = _native.sweep(self._m, self._p, axes, tie_list, bool(untie), settle, cb)
        return Sweep(raw)

    # --------------------------------------------------------------------------- python

    def __repr__(self) -> str:
        changed = self._changed()
        extra = f", params {changed}" if changed else ""
        n = f", n = {self.n}" if self._m.has_array else ""
        return f"Model({self.name!r}{n}, closure {self.closure!r}, {self.n_states} states{extra})"

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Model)
            and other._m.requested == self._m.requested
            and (other.name, other.n, other.closure) == (self.name, self.n, self.closure)
            and np.array_equal(other._p, self._p)
        )

    __hash__ = None  # type: ignore[assignment]


def _count(v: Any) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
        raise OptionError(f"samples must be a whole number, got {v!r}")
    if v < 2:
        raise OptionError(f"samples = {v} must be from 2 to 1000000")
    return int(v)


def _axis(name: str, v: Any) -> List[float]:
    if isinstance(v, tuple) and len(v) == 3:
        a, b, k = v
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise OptionError(f"grid {name} = {v!r}: (start, stop, count) with a whole count >= 1")
        # as the command line's a:b:k: a + i (b - a) / (k - 1)
        a, b, k = float(a), float(b), int(k)
        step = (b - a) / (k - 1) if k > 1 else 0.0
        return [a + step * i for i in range(k)]
    try:
        vals = np.asarray(v, dtype=float).ravel().tolist()
    except (TypeError, ValueError):
        raise OptionError(f"grid {name}: expected a sequence of numbers or (start, stop, count), got {v!r}") from None
    return vals
