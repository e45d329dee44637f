"""The typed results of stirling's analyses.

Each class holds the library's result (what ``stirling ... --json`` prints) in :attr:`raw` and
gives it typed properties with units; every field of :attr:`raw` is also readable as an
attribute, so a field the library adds shows without a change here. Arrays are numpy arrays.
"""

from __future__ import annotations

from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple

import numpy as np

__all__ = [
    "Fields",
    "Pole",
    "Equilibrium",
    "Poles",
    "Margins",
    "Bode",
    "Nyquist",
    "StateSpace",
    "Linearization",
    "Simulation",
    "LimitCycle",
    "Estimate",
    "Stage",
    "Fit",
    "Verdict",
    "RankEntry",
    "Diagnosis",
    "Sweep",
]


def _wrap(v: Any) -> Any:
    if isinstance(v, dict):
        return Fields(v)
    if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
        return [Fields(x) for x in v]
    return v


def _num(v: Optional[float], fmt: str = ".4g") -> str:
    return "none" if v is None else format(v, fmt)


class Fields:
    """A record of named fields (the library's result); fields read as attributes."""

    __slots__ = ("_raw",)

    def __init__(self, raw: Mapping[str, Any]) -> None:
        object.__setattr__(self, "_raw", dict(raw))

    @property
    def raw(self) -> Dict[str, Any]:
        """The fields as the library gives them (lists and dicts, as in the JSON output)."""
        return self._raw

    def to_dict(self) -> Dict[str, Any]:
        """A copy of :attr:`raw`."""
        return dict(self._raw)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        try:
            return _wrap(self._raw[name])
        except KeyError:
            fields = ", ".join(self._raw)
            raise AttributeError(f"{type(self).__name__} has no field {name!r}; its fields: {fields}") from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __getitem__(self, name: str) -> Any:
        return _wrap(self._raw[name])

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._raw))

    def __eq__(self, other: object) -> bool:
        return type(other) is type(self) and other._raw == self._raw  # type: ignore[attr-defined]

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={_short(v)}" for k, v in list(self._raw.items())[:8])
        more = ", ..." if len(self._raw) > 8 else ""
        return f"{type(self).__name__}({inner}{more})"


def _short(v: Any) -> str:
    if isinstance(v, float):
        return format(v, ".6g")
    if isinstance(v, (list, tuple)) and len(v) > 4:
        return f"[{len(v)} items]"
    if isinstance(v, dict):
        return "{...}"
    if isinstance(v, np.ndarray):
        return f"array{v.shape}"
    return repr(v)


# ---------------------------------------------------------------------------------- linear


class Pole(Fields):
    """One pole: ``re`` (1/s), ``im`` (rad/s), ``freq_hz``, ``natural_rad_s``,
    ``damping_ratio``, ``rhp`` (in the right half plane)."""

    @property
    def value(self) -> complex:
        """The pole as a complex number (1/s)."""
        return complex(self._raw["re"], self._raw["im"])

    def __repr__(self) -> str:
        r = self._raw
        flag = ", RHP" if r.get("rhp") else ""
        return f"Pole({r['re']:.6g}{r['im']:+.6g}j, {r['freq_hz']:.4g} Hz, zeta {r['damping_ratio']:.4g}{flag})"


def _poles(rows: Sequence[Mapping[str, Any]]) -> np.ndarray:
    return np.array([complex(p["re"], p["im"]) for p in rows], dtype=complex)


class Equilibrium(Fields):
    """The rest state: ``x`` by Newton on the analytic Jacobian, ``residual`` (max |f|),
    ``scaled_residual`` (1/s), ``iterations``."""

    def __init__(self, raw: Mapping[str, Any], state_names: Sequence[str]) -> None:
        super().__init__(raw)
        object.__setattr__(self, "_names", list(state_names))

    __slots__ = ("_names",)

    @property
    def x(self) -> np.ndarray:
        """The state at rest (the model's state order and units)."""
        return np.asarray(self._raw["x"], dtype=float)

    @property
    def states(self) -> Dict[str, float]:
        """The state at rest by name."""
        return dict(zip(self._names, self._raw["x"]))

    def __repr__(self) -> str:
        r = self._raw
        return f"Equilibrium({len(r['x'])} states, residual {r['residual']:.3g}, scaled {r['scaled_residual']:.3g} 1/s, {r['iterations']} Newton iterations)"


class Poles(Fields):
    """The dynamic poles at rest (the inventory mode of the full closure removed)."""

    def __init__(self, raw: Mapping[str, Any], state_names: Sequence[str]) -> None:
        super().__init__(raw)
        object.__setattr__(self, "_names", list(state_names))

    __slots__ = ("_names",)

    @property
    def values(self) -> np.ndarray:
        """The poles (1/s) as complex numbers, least stable first."""
        return _poles(self._raw["poles"])

    @property
    def table(self) -> List[Pole]:
        """The poles with frequency (Hz, rad/s) and damping ratio."""
        return [Pole(p) for p in self._raw["poles"]]

    @property
    def rhp_count(self) -> int:
        """Poles in the right half plane (a running engine has a pair)."""
        return sum(1 for p in self._raw["poles"] if p["rhp"])

    @property
    def equilibrium(self) -> Equilibrium:
        return Equilibrium(self._raw["equilibrium"], self._names)

    def __len__(self) -> int:
        return len(self._raw["poles"])

    def __iter__(self) -> Iterator[complex]:
        return iter(self.values)

    def __repr__(self) -> str:
        lead = self.table[:2]
        return f"Poles({len(self)} poles, {self.rhp_count} in the RHP; least stable: {', '.join(repr(p.value) for p in lead)})"


class Margins(Fields):
    """Gain and phase margins of the broken loop, as MATLAB's ``margin`` and python-control's
    ``control.margin`` read them.

    ``gain_db`` (dB) at ``phase_crossover_rad_s``, ``phase_deg`` (deg) at
    ``gain_crossover_rad_s``; ``all_gain`` and ``all_phase`` list every crossover.
    """

    @property
    def gain_db(self) -> Optional[float]:
        """The gain margin (dB); negative: the loop is unstable by that much."""
        return self._raw["gain_db"]

    @property
    def phase_crossover_rad_s(self) -> Optional[float]:
        """Where the phase crosses -180 deg (rad/s)."""
        return self._raw["phase_crossover_rad_s"]

    @property
    def phase_deg(self) -> Optional[float]:
        """The phase margin (deg)."""
        return self._raw["phase_deg"]

    @property
    def gain_crossover_rad_s(self) -> Optional[float]:
        """Where the gain crosses 0 dB (rad/s)."""
        return self._raw["gain_crossover_rad_s"]

    def __repr__(self) -> str:
        return (
            f"Margins(Gm {_num(self.gain_db)} dB at {_num(self.phase_crossover_rad_s)} rad/s, "
            f"Pm {_num(self.phase_deg)} deg at {_num(self.gain_crossover_rad_s)} rad/s)"
        )


class Bode(Fields):
    """Bode data of the broken loop: ``w`` (rad/s), ``magnitude``, ``magnitude_db`` (dB),
    ``phase_deg`` (deg, unwrapped)."""

    @property
    def w(self) -> np.ndarray:
        return np.asarray(self._raw["w_rad_s"], dtype=float)

    @property
    def magnitude(self) -> np.ndarray:
        return np.asarray(self._raw["magnitude"], dtype=float)

    @property
    def magnitude_db(self) -> np.ndarray:
        return np.asarray(self._raw["magnitude_db"], dtype=float)

    @property
    def phase_deg(self) -> np.ndarray:
        return np.asarray(self._raw["phase_deg"], dtype=float)

    def __repr__(self) -> str:
        w = self.w
        return f"Bode({len(w)} frequencies from {w[0]:.3g} to {w[-1]:.3g} rad/s)" if len(w) else "Bode(empty)"


class Nyquist(Fields):
    """Nyquist data of the broken loop: ``w`` (rad/s), ``re``, ``im``."""

    @property
    def w(self) -> np.ndarray:
        return np.asarray(self._raw["w"], dtype=float)

    @property
    def re(self) -> np.ndarray:
        return np.asarray(self._raw["re"], dtype=float)

    @property
    def im(self) -> np.ndarray:
        return np.asarray(self._raw["im"], dtype=float)

    def __repr__(self) -> str:
        return f"Nyquist({len(self._raw['w'])} frequencies)"


class StateSpace(Fields):
    """A single-input single-output system ``x' = A x + B u, y = C x + D u``.

    The loop closes with negative unity feedback ``u = -y`` (``closed_loop.A = A - B C``), as
    python-control and MATLAB assume. ``states`` names the coordinates of ``A``.
    """

    def __init__(self, raw: Mapping[str, Any], states: Sequence[str]) -> None:
        super().__init__(raw)
        object.__setattr__(self, "_states", list(states))

    __slots__ = ("_states",)

    def _matrix(self, key: str, shape: Tuple[int, int]) -> np.ndarray:
        """The dense field ``key``, or above 500 states its triplets (``key_sparse``) made dense."""
        m = self._raw.get(key)
        if m is not None:
            return np.asarray(m, dtype=float).reshape(shape)
        t = self._raw[key + "_sparse"]
        out = np.zeros((t["rows"], t["cols"]))
        np.add.at(out, (np.asarray(t["i"], dtype=int), np.asarray(t["j"], dtype=int)), np.asarray(t["v"], dtype=float))
        return out

    @property
    def A(self) -> np.ndarray:  # noqa: N802 (the control engineer's name)
        """The state matrix (1/s), dense (also above 500 states, from its triplets)."""
        n = len(self._states)
        return self._matrix("a", (n, n))

    @property
    def B(self) -> np.ndarray:  # noqa: N802
        """The input column (n x 1), dense (also above 500 states, from its triplets)."""
        return self._matrix("b", (len(self._states), 1))

    @property
    def C(self) -> np.ndarray:  # noqa: N802
        """The output row (1 x n), dense (also above 500 states, from its triplets)."""
        return self._matrix("c", (1, len(self._states)))

    @property
    def D(self) -> np.ndarray:  # noqa: N802
        """The feedthrough (1 x 1)."""
        return self._matrix("d", (1, 1))

    @property
    def states(self) -> List[str]:
        """The names of the coordinates of ``A``."""
        return list(self._states)

    @property
    def poles(self) -> np.ndarray:
        """The eigenvalues of ``A`` (1/s), least stable first."""
        return _poles(self._raw["poles"])

    def matrices(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C, D)``."""
        return self.A, self.B, self.C, self.D

    def to_control(self):
        """A ``control.StateSpace`` (python-control must be installed:
        ``pip install control``), with the state, input and output names."""
        try:
            import control
        except ImportError as e:
            raise ImportError("StateSpace.to_control() needs python-control: pip install control") from e
        return control.ss(
            self.A, self.B, self.C, self.D,
            states=self.states, inputs=[self._raw["input"]], outputs=[self._raw["output"]],
        )

    def __repr__(self) -> str:
        return f"StateSpace({len(self._states)} states, input {self._raw['input']!r}, output {self._raw['output']!r})"


class Linearization(Fields):
    """The model linearized at rest: equilibrium, poles, the loop broken at a pressure-force
    channel with its margins, Bode and Nyquist data and state-space systems."""

    @property
    def report(self) -> Fields:
        """The report of ``stirling linearize --json``."""
        return Fields(self._raw["report"])

    @property
    def equilibrium(self) -> Equilibrium:
        r = self._raw["report"]
        return Equilibrium(r["equilibrium"], r["state_names"])

    @property
    def poles(self) -> np.ndarray:
        """The closed-loop (dynamic) poles (1/s), least stable first."""
        return _poles(self._raw["report"]["poles"])

    @property
    def pole_table(self) -> List[Pole]:
        return [Pole(p) for p in self._raw["report"]["poles"]]

    @property
    def rhp_count(self) -> int:
        return self._raw["report"]["rhp_count"]

    @property
    def open_loop_poles(self) -> np.ndarray:
        """The poles of the broken loop (1/s)."""
        return _poles(self._raw["report"]["loop"]["open_loop_poles"])

    @property
    def channel(self) -> str:
        """The loop channel (``pressure`` or a body)."""
        return self._raw["report"]["loop"]["channel"]

    @property
    def margins(self) -> Margins:
        return Margins(self._raw["report"]["margins"])

    @property
    def bode(self) -> Bode:
        return Bode(self._raw["state_space"]["bode"])

    @property
    def nyquist(self) -> Nyquist:
        return Nyquist(self._raw["nyquist"])

    @property
    def broken_loop(self) -> StateSpace:
        """The loop broken at its channel: python-control's ``control.margin`` on it gives
        :attr:`margins`."""
        ss = self._raw["state_space"]
        return StateSpace(ss["broken_loop"], ss["states"])

    @property
    def closed_loop(self) -> StateSpace:
        ss = self._raw["state_space"]
        return StateSpace(ss["closed_loop"], ss["states"])

    @property
    def state_space(self) -> Fields:
        """The export of ``stirling linearize --ss`` (conventions, reduction, basis)."""
        return Fields(self._raw["state_space"])

    def __repr__(self) -> str:
        r = self._raw["report"]
        m = self.margins
        return (
            f"Linearization({r['model']}, n = {r['n']}, {r['n_states']} states, {r['rhp_count']} RHP poles; "
            f"loop at {self.channel}: Gm {_num(m.gain_db)} dB at {_num(m.phase_crossover_rad_s)} rad/s, "
            f"Pm {_num(m.phase_deg)} deg at {_num(m.gain_crossover_rad_s)} rad/s)"
        )


# ------------------------------------------------------------------------------ simulation


class Simulation(Fields):
    """A run: ``t`` (s, one row per sample) and ``x`` (samples x states, the model's units),
    the states also by name (``sim["P_cold"]``, :attr:`states`), and the solver's counters."""

    def __init__(self, raw: Mapping[str, Any], state_names: Sequence[str]) -> None:
        super().__init__(raw)
        object.__setattr__(self, "_names", list(state_names))

    __slots__ = ("_names",)

    @property
    def t(self) -> np.ndarray:
        """Sample times (s)."""
        return self._raw["t"]

    @property
    def x(self) -> np.ndarray:
        """States at the sample times, one row per sample."""
        return self._raw["x"]

    @property
    def state_names(self) -> List[str]:
        return list(self._names)

    @property
    def states(self) -> Dict[str, np.ndarray]:
        """Each state's samples by name."""
        return {n: self.x[:, i] for i, n in enumerate(self._names)}

    @property
    def final_state(self) -> np.ndarray:
        """The state where the run ended."""
        s = self._raw.get("summary")
        return np.asarray(s["final_state"]) if s else self.x[-1]

    @property
    def stats(self) -> Fields:
        """Solver counters: steps, RHS and Jacobian calls, LU factorizations."""
        return Fields(self._raw["stats"])

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.x[:, self._names.index(name)]
        except ValueError:
            raise KeyError(f"no state {name!r}; the states: {', '.join(self._names)}") from None

    def to_pandas(self):
        """The samples as a pandas DataFrame indexed by ``t`` (pandas must be installed)."""
        import pandas as pd

        return pd.DataFrame(self.x, index=pd.Index(self.t, name="t"), columns=self._names)

    def __repr__(self) -> str:
        s = self.stats.raw
        return f"Simulation({len(self.t)} samples to t = {self.t[-1]:.6g} s, {len(self._names)} states; {s['steps']} steps)"


class LimitCycle(Fields):
    """The limit cycle, refined by shooting: period (s), frequency (Hz), strokes (m), phase
    (deg), pressure amplitudes (Pa), Floquet multipliers, work per cycle (J) and indicated
    power (W), the orbit over one period and each vessel's p-V loop."""

    def __init__(self, raw: Mapping[str, Any], state_names: Sequence[str]) -> None:
        super().__init__(raw)
        object.__setattr__(self, "_names", list(state_names))

    __slots__ = ("_names",)

    @property
    def summary(self) -> Fields:
        """What ``stirling simulate --limit-cycle --json`` prints."""
        return Fields(self._raw["summary"])

    @property
    def period(self) -> float:
        """The period (s)."""
        return self._raw["period"]

    @property
    def frequency_hz(self) -> float:
        return self._raw["summary"]["frequency_hz"]

    @property
    def x_amp(self) -> float:
        """The displacer's amplitude (m)."""
        return self._raw["summary"]["x_amp"]

    @property
    def y_amp(self) -> float:
        """The piston's amplitude (m)."""
        return self._raw["summary"]["y_amp"]

    @property
    def phase_deg(self) -> float:
        """The displacer's phase ahead of the piston (deg)."""
        return self._raw["summary"]["phase_deg"]

    @property
    def p_amp(self) -> np.ndarray:
        """The amplitude of every pressure state (Pa)."""
        return np.asarray(self._raw["summary"]["p_amp"], dtype=float)

    @property
    def floquet(self) -> np.ndarray:
        """Floquet multipliers, largest modulus first (one is 1: the phase along the orbit;
        empty when the cycle was not shot)."""
        return self._raw["floquet"]

    @property
    def work(self) -> float:
        """Gas work per cycle (J), the sum over the vessels of the closed integral of P dV."""
        return self._raw["work"]

    @property
    def work_per_vessel(self) -> Dict[str, float]:
        """Each vessel's work per cycle (J)."""
        return dict(zip(self._raw["vessels"], self._raw["work_per_vessel"].tolist()))

    @property
    def power(self) -> float:
        """Indicated power (W): work per cycle times frequency."""
        return self._raw["summary"]["power_w"]

    @property
    def orbit(self) -> np.ndarray:
        """States over one period (uniform samples, last = first)."""
        return self._raw["orbit"]

    @property
    def orbit_t(self) -> np.ndarray:
        """Times of :attr:`orbit` from the section crossing (s)."""
        return self._raw["orbit_t"]

    @property
    def pv(self) -> Dict[str, Tuple[np.ndarray, np.ndarray]]:
        """Each vessel's loop over the orbit: ``(volume (m^3), pressure (Pa))``."""
        v, p = self._raw["volume"], self._raw["pressure"]
        return {name: (v[i], p[i]) for i, name in enumerate(self._raw["vessels"])}

    @property
    def settled(self) -> Simulation:
        """The settling run from the start to the cycle."""
        return Simulation(self._raw["settled"], self._names)

    @property
    def route(self) -> str:
        """``dense``, ``block``, ``krylov`` (shot) or ``settled`` (measured, not shot)."""
        return self._raw["route"]

    def __repr__(self) -> str:
        return (
            f"LimitCycle({self.frequency_hz:.4f} Hz, x {1e3 * self.x_amp:.3f} mm, y {1e3 * self.y_amp:.3f} mm, "
            f"phase {self.phase_deg:.2f} deg, {self.work:.5f} J per cycle, {self.power:.4f} W; shooting {self.route})"
        )


# ------------------------------------------------------------------------------------- fit


class Estimate(Fields):
    """One estimated quantity: ``initial``, ``value``, ``std_error``, the 95 % interval
    ``ci_low``..``ci_high`` (the parameter's unit), ``model_param`` (else an offset or an
    initial state)."""

    @property
    def value(self) -> float:
        return self._raw["value"]

    @property
    def interval(self) -> Tuple[float, float]:
        """The 95 % interval."""
        return (self._raw["ci_low"], self._raw["ci_high"])

    def covers(self, v: float) -> bool:
        """Whether ``v`` lies in the 95 % interval."""
        return self._raw["ci_low"] <= v <= self._raw["ci_high"]

    def __repr__(self) -> str:
        r = self._raw
        return f"Estimate({r['name']} = {r['value']:.6g} +- {r['std_error']:.3g}, 95 % [{r['ci_low']:.6g}, {r['ci_high']:.6g}])"


class Stage(Fields):
    """One stage of the fit: estimates, their correlation and covariance, fit percentages,
    convergence."""

    @property
    def name(self) -> str:
        return self._raw["stage"]

    @property
    def estimates(self) -> Dict[str, Estimate]:
        return {e["name"]: Estimate(e) for e in self._raw["stats"]["estimates"]}

    @property
    def correlation(self) -> np.ndarray:
        """Correlations of the estimates (their order in :attr:`estimates`)."""
        return np.asarray(self._raw["stats"]["correlation"], dtype=float)

    @property
    def covariance(self) -> np.ndarray:
        """Covariance of the estimates: correlation times the standard errors."""
        se = np.array([e["std_error"] for e in self._raw["stats"]["estimates"]], dtype=float)
        return self.correlation * np.outer(se, se)

    @property
    def fits(self) -> List[Fields]:
        """Fit percentage and rms per channel and block."""
        return [Fields(f) for f in self._raw["fits"]]

    @property
    def converged(self) -> bool:
        return self._raw["converged"]

    @property
    def warnings(self) -> List[str]:
        return list(self._raw["stats"]["warnings"])

    def __repr__(self) -> str:
        names = ", ".join(self.estimates)
        ok = "converged" if self.converged else "NOT converged"
        return f"Stage({self.name}: {names}; {self._raw['iterations']} iterations, {ok})"


class Fit(Fields):
    """The two-stage identification: parameters after the fit, each stage's estimates with
    intervals and covariance, the optional multiple-shooting refinement, the free-run check,
    and the measured-vs-model series (:attr:`series`)."""

    __slots__ = ("_series",)

    def __init__(self, raw: Mapping[str, Any]) -> None:
        raw = dict(raw)
        object.__setattr__(self, "_series", raw.pop("series", {}))
        super().__init__(raw)

    @property
    def params(self) -> Dict[str, float]:
        """Every parameter after the fit."""
        return {k: v for k, v in self._raw["params"]}

    @property
    def stage1(self) -> Optional[Stage]:
        s = self._raw.get("stage1")
        return Stage(s) if s else None

    @property
    def stage2(self) -> Optional[Stage]:
        s = self._raw.get("stage2")
        return Stage(s) if s else None

    @property
    def stages(self) -> List[Stage]:
        return [s for s in (self.stage1, self.stage2) if s is not None]

    @property
    def estimates(self) -> Dict[str, Estimate]:
        """The estimates of both stages (stage 1 first)."""
        out: Dict[str, Estimate] = {}
        for s in reversed(self.stages):
            out.update(s.estimates)
        return out

    @property
    def converged(self) -> bool:
        """Whether every stage converged (else the estimates are not an optimum)."""
        return all(s.converged for s in self.stages)

    @property
    def series(self) -> Dict[str, List[Fields]]:
        """Measured vs model per stage (``stage1``, ``stage2``, ``free_run``): ``channel``,
        ``t`` (s), ``measured``, ``model`` (arrays in the channel's unit)."""
        return {k: [Fields(x) for x in v] for k, v in self._series.items()}

    def __repr__(self) -> str:
        est = ", ".join(f"{k} = {e.value:.4g}" for k, e in list(self.estimates.items())[:6])
        ok = "" if self.converged else ", NOT converged"
        return f"Fit({self._raw['model']}, n = {self._raw['n']}: {est}{ok})"


# -------------------------------------------------------------------------------- diagnose


class Verdict(Fields):
    """The verdict: ``verdict`` (``effect``, ``unexplained`` or ``no_significant_gap``), the
    leading ``effect``, its closure fraction with interval, the ``gap`` (noise variances) and
    the ``reason``."""

    def __repr__(self) -> str:
        r = self._raw
        eff = r.get("effects") or ([r["effect"]] if r.get("effect") else [])
        named = f" {', '.join(eff)}" if eff else ""
        return f"Verdict({r['verdict']}{named}: {r['reason']})"


class RankEntry(Fields):
    """A candidate effect: score, p-value, held-out BIC change, closure fraction with 95 %
    interval, fitted parameters with intervals."""

    def __repr__(self) -> str:
        r = self._raw
        return f"RankEntry({r['effect']}: p {r['p_value']:.3g}, dBIC {_num(r.get('delta_bic'))}, closure {_num(r.get('closure_fraction'))})"


class Diagnosis(Fields):
    """The sim-to-real gap diagnosis: the gap of the calibrated nominal model, where it lies,
    the candidates ranked, the steps of the explanation and the verdict (the library's
    ``Diagnosis``, as ``stirling diagnose --json`` prints it)."""

    @property
    def verdict(self) -> Verdict:
        return Verdict(self._raw["verdict"])

    @property
    def ranking(self) -> List[RankEntry]:
        return [RankEntry(r) for r in self._raw.get("ranking", [])]

    @property
    def steps(self) -> List[Fields]:
        """The steps of a stepwise explanation (empty when the library gives none)."""
        return [Fields(s) for s in self._raw.get("steps", [])]

    @property
    def effect(self) -> Optional[str]:
        """The leading effect named (``None`` for a clean record)."""
        return self._raw["verdict"].get("effect")

    def __repr__(self) -> str:
        return f"Diagnosis({self._raw['model']}, n = {self._raw['n']}: {self.verdict!r})"


# ----------------------------------------------------------------------------------- sweep


class Sweep(Fields):
    """A design sweep: per grid point the swept values, the outcome (``runs``, ``stable``,
    ``unstable_no_cycle``, ``unstable``, ``failed``), the dominant pole at rest and the limit
    cycle (frequency (Hz), strokes (m), phase (deg), work (J), power (W))."""

    COLUMNS = ("rhp", "growth_rate", "pole_hz", "frequency_hz", "x_stroke", "y_stroke", "phase_deg", "work_j", "power_w")

    @property
    def axes(self) -> Dict[str, np.ndarray]:
        return {a["name"]: np.asarray(a["values"], dtype=float) for a in self._raw["axes"]}

    @property
    def points(self) -> List[Fields]:
        return [Fields(p) for p in self._raw["points"]]

    @property
    def outcome(self) -> np.ndarray:
        return np.array([p["outcome"] for p in self._raw["points"]], dtype=object)

    def column(self, name: str) -> np.ndarray:
        """One result per point as floats (NaN where a point has none)."""
        if name in self.axes:
            k = list(self.axes).index(name)
            return np.array([p["values"][k] for p in self._raw["points"]], dtype=float)
        if name not in self.COLUMNS:
            raise KeyError(f"no column {name!r}; columns: {', '.join(list(self.axes) + list(self.COLUMNS))}")
        return np.array([np.nan if p[name] is None else p[name] for p in self._raw["points"]], dtype=float)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.column(name)

    def to_pandas(self):
        """One row per point: the swept values, the outcome and the results (pandas)."""
        import pandas as pd

        cols: Dict[str, Any] = {n: self.column(n) for n in self.axes}
        cols["outcome"] = self.outcome
        cols.update({c: self.column(c) for c in self.COLUMNS})
        cols["error"] = [p.get("error") for p in self._raw["points"]]
        return pd.DataFrame(cols)

    def __repr__(self) -> str:
        runs = int(np.sum(self.outcome == "runs")) if self._raw["points"] else 0
        axes = ", ".join(f"{k} ({len(v)})" for k, v in self.axes.items())
        return f"Sweep({self._raw['model']} over {axes}: {len(self._raw['points'])} points, {runs} run)"
