"""Measured records: the channels a fit and a diagnosis read, from arrays, pandas, a CSV file
or the virtual rig."""

from __future__ import annotations

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from .results import Fields

__all__ = ["Record", "RigRecord", "read_csv"]

PathLike = Union[str, "os.PathLike[str]"]


class Record:
    """A measured record: time ``t`` (s, strictly increasing) and channels by name.

    The seed's channels are ``p`` (cold-side absolute pressure, Pa), ``p_hot`` (Pa), ``x``
    (displacer position, m) and ``y`` (piston position, m); any other name is the column of a
    sensor a model declares (in that sensor's unit). Every channel has one finite value per
    sample of ``t``; a fit or a diagnosis also needs uniform sampling.

    >>> rec = Record(t, p=p, x=x, y=y)          # or Record(t, {"p": p, "x": x, "y": y})
    >>> rec["p"], rec.channels, rec.to_pandas()
    """

    __slots__ = ("_native",)

    def __init__(
        self,
        t: Any,
        channels: Optional[Mapping[str, Any]] = None,
        *,
        source: str = "arrays",
        **named: Any,
    ) -> None:
        chans: Dict[str, Any] = dict(channels or {})
        for k, v in named.items():
            if k in chans:
                from .errors import RecordError

                raise RecordError(f"channel `{k}` is given twice")
            chans[k] = v
        self._native = _native.NativeRecord(t, chans, source)

    @classmethod
    def _wrap(cls, native: "_native.NativeRecord") -> "Record":
        r = cls.__new__(cls)
        object.__setattr__(r, "_native", native)
        return r

    @classmethod
    def from_pandas(cls, df: Any, time: Optional[str] = "t", source: str = "pandas") -> "Record":
        """A record from a DataFrame: time from the column ``time`` (or the index when
        ``time`` is ``None`` or not a column), every other column a channel."""
        if time is not None and time in df.columns:
            t = df[time].to_numpy(dtype=float)
            rest = df.drop(columns=[time])
        else:
            t = np.asarray(df.index, dtype=float)
            rest = df
        return cls(t, {str(c): rest[c].to_numpy(dtype=float) for c in rest.columns}, source=source)

    @property
    def t(self) -> np.ndarray:
        """Sample times (s)."""
        return self._native.t

    @property
    def channels(self) -> List[str]:
        """The channels present: p, p_hot, x, y in that order, then the others."""
        return self._native.channels()

    @property
    def source(self) -> str:
        """Where the record came from (a file name, ``arrays``, ``rig``)."""
        return self._native.source

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "t":
            return self.t
        return self._native.channel(name)

    def __contains__(self, name: object) -> bool:
        return name == "t" or name in self.channels

    def __len__(self) -> int:
        return len(self._native)

    def __iter__(self) -> Iterator[str]:
        return iter(["t"] + self.channels)

    def to_dict(self) -> Dict[str, np.ndarray]:
        """``{"t": ..., channel: ...}`` as arrays."""
        out = {"t": self.t}
        out.update({c: self[c] for c in self.channels})
        return out

    def to_pandas(self):
        """The record as a pandas DataFrame indexed by ``t`` (pandas must be installed)."""
        import pandas as pd

        return pd.DataFrame({c: self[c] for c in self.channels}, index=pd.Index(self.t, name="t"))

    def slice(self, a: float, b: float) -> "Record":
        """The samples with ``a <= t <= b`` (s), time kept absolute."""
        return Record._wrap(self._native.slice(a, b))

    def write_csv(self, path: PathLike, comments: Sequence[str] = (), force: bool = False) -> None:
        """Write the record as CSV (10 significant digits, as the rig writes); an existing
        file is refused unless ``force``."""
        self._native.write_csv(os.fspath(path), list(comments), force)

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` (s)."""
        t = self.t
        return float(t[-1] - t[0])

    def __repr__(self) -> str:
        t = self.t
        return f"{type(self).__name__}({len(t)} samples, {t[0]:.6g} to {t[-1]:.6g} s, channels {', '.join(self.channels)}; from {self.source})"


class RigRecord(Record):
    """A record the virtual rig wrote, with its truth: the model and parameters it ran, the
    effects switched on, noise, offsets and seed (:attr:`truth`)."""

    __slots__ = ("_truth",)

    @classmethod
    def _from(cls, native: "_native.NativeRecord", truth: Mapping[str, Any]) -> "RigRecord":
        r = cls._wrap(native)
        object.__setattr__(r, "_truth", dict(truth))
        return r  # type: ignore[return-value]

    @property
    def truth(self) -> Fields:
        """What the rig ran (the sidecar ``FILE.truth.json`` of ``stirling rig``)."""
        return Fields(self._truth)

    def __repr__(self) -> str:
        fx = self._truth.get("active_effects") or ["none"]
        return f"{super().__repr__()[:-1]}; truth {self._truth.get('model')} with effects {', '.join(fx)})"


def read_csv(path: PathLike) -> Record:
    """Read a measured record from a CSV file: a header with ``t`` and any of ``p``,
    ``p_hot``, ``x``, ``y`` and other columns by name, ``#`` comment lines. A malformed file
    raises :class:`~stirling.errors.RecordError` naming the row and the column."""
    return Record._wrap(_native.read_csv(os.fspath(path)))


def rig(
    model: str,
    *,
    n: Optional[int] = None,
    params: Optional[Mapping[str, float]] = None,
    effects: Optional[Mapping[str, float]] = None,
    truth: Optional[str] = None,
    t_end: float = 1.0,
    settle: float = 0.0,
    rate: float = 2000.0,
    noise_p: float = 50.0,
    noise_x: float = 20e-6,
    noise: Optional[Mapping[str, float]] = None,
    offset_p: float = 0.0,
    offset_x: float = 0.0,
    offset_y: float = 0.0,
    x0: float = 2e-3,
    seed: int = 1,
    channels: Sequence[str] = ("p", "x", "y"),
) -> RigRecord:
    """The virtual test rig: run a truth model and measure it as a test rig would.

    ``model`` is ``cv1``, ``nsection`` or ``nsection_ext`` (aliases ``order5``, ``order7``,
    ``order8``) or a registered engine; ``n`` its regenerator sections; ``params`` the truth's
    parameters by name; ``effects`` the effects switched on, by name or effect parameter
    (``{"leak": 2e-8}``, ``{"coulomb": 0.02}``; see :func:`stirling.effects`); ``truth`` a cause
    outside the library instead (``h_speed``, ``spring_cubic``, strength in ``params``).

    The record is ``t_end`` s long (after ``settle`` s discarded) at ``rate`` Hz, with noise of
    standard deviation ``noise_p`` (Pa) on pressures and ``noise_x`` (m) on positions (``noise``
    by channel overrides them), offsets ``offset_p`` (Pa), ``offset_x``, ``offset_y`` (m), the
    displacer started ``x0`` m from rest, noise seed ``seed``; ``channels`` as written
    (``p``, ``x``, ``y`` by default, ``p_hot`` on request).
    """
    native, tr = _native.rig(
        model, n, None if params is None else dict(params), None if effects is None else dict(effects),
        truth, t_end, settle, rate, noise_p, noise_x, None if noise is None else dict(noise),
        offset_p, offset_x, offset_y, x0, seed, list(channels),
    )
    return RigRecord._from(native, tr)


def _as_native(record: Union[Record, Any]) -> "_native.NativeRecord":
    """A :class:`Record`, or a DataFrame, as the native record."""
    if isinstance(record, Record):
        return record._native
    if hasattr(record, "columns") and hasattr(record, "index"):
        return Record.from_pandas(record)._native
    from .errors import RecordError

    raise RecordError(f"expected a stirling.Record (or a pandas DataFrame), got {type(record).__name__}")


def _block(b: Optional[Tuple[float, float]], name: str) -> Optional[Tuple[float, float]]:
    if b is None:
        return None
    try:
        a, z = b
        return (float(a), float(z))
    except (TypeError, ValueError):
        from .errors import OptionError

        raise OptionError(f"{name} must be a pair (start, end) in seconds, got {b!r}") from None
