"""The one record type every reader, the catalogue and the generator return.

A :class:`Record` holds a uniformly sampled ground acceleration with one or more
horizontal components, always in SI units (m/s²); readers convert at the edge.
Derived time histories use the trapezoidal rule with zero initial conditions and
no baseline correction, the same convention as ``../shared/records/raw/SOURCES.md``:

.. math::

    v_k = \\sum_{j<k} \\tfrac{\\Delta t}{2}(a_j + a_{j+1}), \\qquad
    d_k = \\sum_{j<k} \\tfrac{\\Delta t}{2}(v_j + v_{j+1}).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.file_units import STANDARD_GRAVITY  # one value for every g <-> m/s² conversion

__all__ = ["Record", "STANDARD_GRAVITY", "cumulative_trapezoid"]


def cumulative_trapezoid(values: np.ndarray, dt: float) -> np.ndarray:
    """Cumulative trapezoidal integral along axis 0, starting at zero.

    Parameters
    ----------
    values : ndarray, shape (n, ...)
        Samples to integrate.
    dt : float
        Uniform step [s].

    Returns
    -------
    ndarray
        Same shape as ``values``; row 0 is zero.
    """
    values = np.asarray(values, dtype=float)
    out = np.zeros_like(values)
    if values.shape[0] > 1:
        out[1:] = np.cumsum(0.5 * dt * (values[1:] + values[:-1]), axis=0)
    return out


@dataclass(frozen=True, eq=False)
class Record:
    """A uniformly sampled ground-acceleration record.

    Parameters
    ----------
    name : str
        Short name (e.g. ``"newhall"``, ``"synthetic-kobe"``).
    dt : float
        Sampling step [s]; positive and finite.
    acceleration : ndarray, shape (n_samples, n_components)
        Ground acceleration [m/s²]. A 1-D array is taken as one component. Stored as a
        read-only float64 copy.
    labels : tuple of str
        One label per component (e.g. ``("FN", "FP")``; for benchmark records the first is
        the component on x).
    source : str
        File path, or ``"synthetic: ..."`` describing how it was generated.
    synthetic : bool
        True for generated motions; plots and reports say so.
    metadata : dict
        Anything else (event, station, units read, orientation, flaws, ...).

    Raises
    ------
    InputError
        If ``dt`` is not positive and finite, the array is empty, has the wrong number of
        dimensions, holds NaN or infinite values, or the labels do not match the components.
    """

    name: str
    dt: float
    acceleration: np.ndarray
    labels: tuple[str, ...] = ()
    source: str = ""
    synthetic: bool = False
    metadata: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        dt = float(self.dt)
        if not math.isfinite(dt) or dt <= 0.0:
            raise InputError(f"record {self.name!r}: dt = {self.dt!r} s; expected a positive finite time step")
        acc = np.array(self.acceleration, dtype=float, copy=True)
        if acc.ndim == 1:
            acc = acc[:, None]
        if acc.ndim != 2 or acc.shape[0] < 2 or acc.shape[1] < 1:
            raise InputError(f"record {self.name!r}: acceleration has shape {np.shape(self.acceleration)}; "
                             "expected (n_samples >= 2, n_components >= 1)")
        bad = ~np.isfinite(acc)
        if bad.any():
            row, col = np.argwhere(bad)[0]
            raise InputError(f"record {self.name!r}: non-finite acceleration {acc[row, col]} at sample {row}, "
                             f"component {col}")
        acc.setflags(write=False)
        labels = tuple(str(s) for s in self.labels) or tuple(f"component {i + 1}" for i in range(acc.shape[1]))
        if len(labels) != acc.shape[1]:
            raise InputError(f"record {self.name!r}: {len(labels)} labels for {acc.shape[1]} components")
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "acceleration", acc)
        object.__setattr__(self, "labels", labels)
        object.__setattr__(self, "metadata", dict(self.metadata))

    # ----------------------------------------------------------------- shape and time
    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.acceleration.shape[0])

    @property
    def n_components(self) -> int:
        """Number of components."""
        return int(self.acceleration.shape[1])

    @property
    def duration(self) -> float:
        """Record length ``n_samples * dt`` [s] (each sample stands for one step; 6000 × 0.005 s = 30 s)."""
        return self.n_samples * self.dt

    @property
    def time(self) -> np.ndarray:
        """Sample times ``k * dt``, k = 0 … n−1 [s]."""
        return np.arange(self.n_samples) * self.dt

    # ----------------------------------------------------------------- derived histories
    def velocity(self) -> np.ndarray:
        """Ground velocity [m/s] by the trapezoidal rule from rest, shape (n, n_components)."""
        return cumulative_trapezoid(self.acceleration, self.dt)

    def displacement(self) -> np.ndarray:
        """Ground displacement [m] by double trapezoidal integration from rest."""
        return cumulative_trapezoid(self.velocity(), self.dt)

    @property
    def pga(self) -> np.ndarray:
        """Peak ground acceleration per component [m/s²]."""
        return np.max(np.abs(self.acceleration), axis=0)

    @property
    def pga_g(self) -> np.ndarray:
        """Peak ground acceleration per component in g (÷ 9.80665 m/s²)."""
        return self.pga / STANDARD_GRAVITY

    @property
    def pgv(self) -> np.ndarray:
        """Peak ground velocity per component [m/s] (trapezoidal, no baseline correction)."""
        return np.max(np.abs(self.velocity()), axis=0)

    @property
    def pgd(self) -> np.ndarray:
        """Peak ground displacement per component [m] (no baseline correction)."""
        return np.max(np.abs(self.displacement()), axis=0)

    # ----------------------------------------------------------------- new records
    def replace(self, **changes: Any) -> "Record":
        """Return a copy with some fields changed (validated again).

        Parameters
        ----------
        **changes
            Field names and their new values (any field of :class:`Record`); the copy is validated like a
            new record.
        """
        return dataclasses.replace(self, **changes)

    def scaled(self, factor: float) -> "Record":
        """Return the record with its acceleration multiplied by ``factor`` (noted in the metadata).

        Parameters
        ----------
        factor : float
            Dimensionless multiplier of the acceleration (e.g. 1.5 for a record scaled to 150 %).
        """
        factor = float(factor)
        if not math.isfinite(factor):
            raise InputError(f"record {self.name!r}: scale factor {factor} is not finite")
        meta = dict(self.metadata)
        meta["scale_factor"] = meta.get("scale_factor", 1.0) * factor
        return self.replace(acceleration=self.acceleration * factor, metadata=meta)

    def select(self, components: tuple[int, ...] | list[int]) -> "Record":
        """Return a record holding the given components in the given order.

        Parameters
        ----------
        components : tuple[int, ...] | list[int]
            0-based indices of the components to keep, in the order they will have.
        """
        idx = [int(i) for i in components]
        for i in idx:
            if not -self.n_components <= i < self.n_components:
                raise InputError(f"record {self.name!r}: component {i} does not exist "
                                 f"(it has {self.n_components})")
        return self.replace(acceleration=self.acceleration[:, idx], labels=tuple(self.labels[i] for i in idx))

    def summary(self) -> dict[str, Any]:
        """Plain-JSON summary: name, dt, samples, duration, PGA [m/s² and g], PGV [m/s], PGD [m], and
        ``units_assumed``: the units the file's values were read in and why
        (:func:`units_assumed`)."""
        return {
            "name": self.name,
            "synthetic": self.synthetic,
            "source": self.source,
            "dt_s": self.dt,
            "n_samples": self.n_samples,
            "duration_s": self.duration,
            "labels": list(self.labels),
            "pga_m_s2": [float(x) for x in self.pga],
            "pga_g": [float(x) for x in self.pga_g],
            "pgv_m_s": [float(x) for x in self.pgv],
            "pgd_m": [float(x) for x in self.pgd],
            "units_assumed": _units_assumed(self),
        }

    def __repr__(self) -> str:  # arrays are long; keep the repr short
        kind = "synthetic " if self.synthetic else ""
        return (f"Record({kind}{self.name!r}, dt={self.dt:g} s, n={self.n_samples}, "
                f"components={self.labels}, pga_g={np.round(self.pga_g, 3).tolist()})")


def _units_assumed(record: Record) -> str:
    return units_assumed(record)


def units_assumed(record: Record) -> str:
    """The units the record's values were read in and where that came from, one short phrase.

    ``"cm/s2 (benchmark default cm/s2 (not in the header))"``, ``"g (file header)"``,
    ``"m/s2 (generated)"``; records built in Python without a reader give ``"m/s2 (given in SI)"``.

    Parameters
    ----------
    record : Record
        The record whose metadata (``units``, ``units_source``) is read.
    """
    meta = record.metadata
    if "units_assumed" in meta:
        return str(meta["units_assumed"])
    units = meta.get("units_in_file")
    if units is None:
        return "m/s2 (generated)" if record.synthetic else "m/s2 (given in SI)"
    origin = meta.get("units_from")
    if origin is None:
        origin = {"at2": "file header", "single": "--units / default g"}.get(meta.get("format"), "file")
    text = f"{units} ({origin})"
    if str(meta.get("dt_from", "")).startswith("benchmark default"):
        # read with --format benchmark and no step: the benchmark's, an assumption like its units
        text += f", at a step of {record.dt:g} s (the benchmark's; not in the file: give --dt)"
    return text
