"""Tests prepared for the residual loop: motions, forces, training and held-out samples.

From a list of :class:`~damper.io.data.DamperTest` records this module builds

* one :class:`~damper.diagnosis.effects.Motion` per test, with the acceleration the ``inertia`` term needs
  (Savitzky-Golay derivative of the measured velocity over about 1/20 of the dominant period,
  so that measurement noise is not amplified);
* the *warm-up* of each test (the samples before the first displacement reversal, where a model
  started from rest cannot match a device that was already moving) -- excluded everywhere;
* the split into training and held-out samples: either the last ``holdout`` fraction of each
  test, taken up to its last sample the screening did not flag (a rig at rest after the test or a
  corrupted end is not held-out data; the model is still simulated over the whole test, so the
  held-out samples are a true prediction from the fitted parameters), or separate validation
  tests.

The coil input is the voltage [V] when the tests give voltages, the current [A] when they give
currents (the fitted model then reads the current as its input); mixing both is an error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest
from damper.io.reader import check_coil_inputs
from damper.io.screening import (band_edge, derivative_window, dominant_frequency, next_reversal, screening_of,
                                 smoothed_derivative)
from damper.diagnosis.effects import Motion
from damper.identification.metrics import relative_rms_error

__all__ = ["DiagnosisData", "acceleration_from_velocity", "acceleration_window",
           "reach_of_flagged", "DEFAULT_HOLDOUT"]

#: Default held-out fraction of each test.
DEFAULT_HOLDOUT = 0.25
#: At most this many distinct input levels become law nodes; more (or varying input) use a grid.
_MAX_LEVEL_NODES = 6
_GRID_NODES = 4
#: The grid of nodes spans these percentiles of the input (each end).
_NODE_PERCENTILE = 2.5


def acceleration_window(t: np.ndarray, velocity: np.ndarray,
                        displacement: np.ndarray | None = None) -> int:
    """Samples in the Savitzky-Golay window of :func:`acceleration_from_velocity` (odd, >= 5).

    0 when the derivative falls back to :func:`numpy.gradient` (non-uniform sampling, fewer than
    7 samples, or a window as long as the test), whose reach is one sample each side.

    Parameters
    ----------
    t, velocity, displacement : np.ndarray
        As for :func:`acceleration_from_velocity`.
    """
    t = np.asarray(t, dtype=float)
    velocity = np.asarray(velocity, dtype=float)
    if t.size < 7:
        return 0
    x = velocity if displacement is None else np.asarray(displacement, dtype=float)
    f = dominant_frequency(t, x)
    # a uniform grid (the screening restored it): a twentieth of the shortest period
    return derivative_window(t, 1.0 / f if f > 0 else math.inf, band_edge(t, velocity), per_period=20.0,
                             jitter=1e-6)


def acceleration_from_velocity(t: np.ndarray, velocity: np.ndarray,
                               displacement: np.ndarray | None = None, window: int | None = None) -> np.ndarray:
    """Acceleration [m/s²] as the Savitzky-Golay derivative (order 2) of the velocity.

    The window (:func:`acceleration_window`) spans about 1/20 of the dominant period of the
    displacement, or 1/10 of the period at the velocity's band edge (the frequency below which
    :data:`damper.io.screening.BAND_EDGE_SHARE` of its variance lies,
    :func:`damper.io.screening.band_edge`) when that is shorter, and at least 5 samples:
    the derivative follows the motion but not the noise. The band edge matters for broadband
    tests: the Dyke recordings' random displacement has its largest peak near 1 Hz and its
    velocity up to 50 Hz, where a window of a twentieth of the dominant period (50 ms) would
    smooth away the acceleration the ``inertia`` term needs. A periodic test's band edge is its
    frequency, so its window is the dominant period's. Non-uniform sampling falls back to
    :func:`numpy.gradient`.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s].
    velocity : np.ndarray
        Velocity [m/s] at ``t``.
    displacement : np.ndarray | None, optional
        Displacement [m] at ``t``, to find the dominant period; None: from the velocity.
    window : int | None, optional
        :func:`acceleration_window` of these samples when the caller has it already.
    """
    t = np.asarray(t, dtype=float)
    velocity = np.asarray(velocity, dtype=float)
    if window is None:
        window = acceleration_window(t, velocity, displacement)
    return smoothed_derivative(t, velocity, window)


def reach_of_flagged(mask: np.ndarray, reach: int) -> np.ndarray:
    """``mask`` with every sample within ``reach`` samples of a flagged one flagged too.

    A derived channel computed over a window (the acceleration's Savitzky-Golay derivative)
    carries a flagged sample's value into its neighbours: they are excluded with it.

    Parameters
    ----------
    mask : np.ndarray
        True where a sample is usable.
    reach : int
        Samples each side that a window reaches (half the window, rounded down).
    """
    mask = np.asarray(mask, dtype=bool)
    if reach <= 0 or mask.all():
        return mask
    bad = (~mask).astype(np.int64)
    # a running sum over a window of 2 reach + 1 samples counts the flagged ones in reach
    padded = np.concatenate([np.zeros(reach + 1, np.int64), np.cumsum(bad),
                             np.full(reach, int(bad.sum()), np.int64)])
    count = padded[2 * reach + 1:] - padded[:mask.size]
    return count == 0


def _input_of(test: DamperTest) -> tuple[str, np.ndarray]:
    if test.voltage is not None:
        return "voltage", np.asarray(test.voltage, dtype=float)
    if test.current is not None:
        return "current", np.asarray(test.current, dtype=float)
    return "none", np.zeros(test.n_samples)


@dataclass(frozen=True)
class DiagnosisData:
    """Tests prepared for the loop (build with :meth:`from_tests`).

    Parameters
    ----------
    source_levels : np.ndarray | None, optional
        Coil-input levels of the full tests, kept by a decimated copy
        (:func:`damper.diagnosis.coarse.decimate`); None: from ``motions``.
    _source_nodes : np.ndarray | None, optional
        Law nodes of the full tests, kept by a decimated copy; None: from ``motions``.
    input_recorded : bool, optional
        Whether the files recorded the coil input (False: none did; 0 V assumed, and said).

    Attributes
    ----------
    motions : tuple of Motion
        One per test (fitting tests first, then validation tests).
    forces : tuple of ndarray
        Measured forces [N].
    train, heldout : tuple of bool ndarray
        Samples used for fitting, and for the held-out errors and traces.
    input_name : str
        ``"voltage"`` [V] or ``"current"`` [A] (``"voltage"`` at 0 V when the tests give neither:
        ``input_recorded`` is then False).
    holdout : float or None
        Held-out fraction of each test, or ``None`` when validation tests were given.
    """

    motions: tuple
    forces: tuple
    train: tuple
    heldout: tuple
    input_name: str
    holdout: float | None
    #: Coil-input levels of the tests these were decimated from (:mod:`~damper.diagnosis.coarse`),
    #: so that a coarse copy keeps the nodes and input range of the full tests.
    source_levels: np.ndarray | None = None
    _source_nodes: np.ndarray | None = None
    #: Whether the files recorded the coil input; False: none did, and 0 V is assumed (a
    #: passive test, or a column left out), which the report says.
    input_recorded: bool = True

    @classmethod
    def from_tests(cls, tests: Sequence[DamperTest], holdout: float | None = DEFAULT_HOLDOUT,
                   validate: Sequence[DamperTest] | None = None) -> "DiagnosisData":
        """Prepare ``tests`` (and optional ``validate`` tests) for the loop.

        Parameters
        ----------
        tests : sequence of DamperTest
            Tests to fit.
        holdout : float, optional
            Fraction (0 < holdout < 1) of each test, at its end, held out; ignored when
            ``validate`` is given.
        validate : sequence of DamperTest, optional
            Separate tests for the held-out errors (then every sample of ``tests`` is fitted).

        Raises
        ------
        InputError
            No tests, a mix of voltage and current, a bad holdout fraction, or too few samples.
        """
        tests = list(tests)
        validate = list(validate or [])
        if not tests:
            raise InputError("diagnose: expected at least one test to fit")
        for test in tests + validate:
            if not isinstance(test, DamperTest):
                raise InputError(f"diagnose: expected DamperTest objects, got {type(test).__name__}")
        kinds = {_input_of(t)[0] for t in tests + validate} - {"none"}
        if len(kinds) > 1:
            raise InputError("diagnose: the tests mix voltage and current inputs; expected one kind")
        recorded = check_coil_inputs([(t.name or t.source or "a test", t) for t in tests + validate], "diagnose")
        input_name = kinds.pop() if kinds else "voltage"
        if not validate:
            if holdout is None or not (isinstance(holdout, (int, float)) and 0.0 < holdout < 1.0):
                raise InputError(f"--holdout: expected a fraction 0 < holdout < 1, got {holdout!r}")
        motions, forces, train, held = [], [], [], []
        for test, is_validation in [(t, False) for t in tests] + [(t, True) for t in validate]:
            t = np.asarray(test.time, dtype=float)
            x = np.asarray(test.displacement, dtype=float)
            xd = np.asarray(test.velocity, dtype=float)
            _, v = _input_of(test)
            window = acceleration_window(t, xd, x)
            motion = Motion(t, x, xd, acceleration_from_velocity(t, xd, x, window), v,
                            name=test.name or test.source or f"test {len(motions) + 1}")
            # the warm-up ends at the first reversal (none: there is no warm-up to leave out)
            start = next_reversal(x, 0)
            start = 0 if start >= x.size else start
            usable = np.zeros(t.size, dtype=bool)
            usable[start:] = True
            if test.mask is not None and test.mask.any():
                # a flagged tail (a rig at rest after the test, a corrupted end) is not data: the
                # held-out fraction is taken of the test up to its last unflagged sample, so
                # that such a tail does not take the place of held-out data
                usable[int(np.flatnonzero(test.mask)[-1]) + 1:] = False
            if usable.sum() < 10:
                raise InputError(f"{motion.name}: fewer than 10 samples after the first reversal"
                                 + ("" if test.mask is None else " and before the flagged tail "
                                    f"({screening_of(test).brief()}; --keep-flagged keeps it)"))
            if validate:
                tr = usable if not is_validation else np.zeros(t.size, dtype=bool)
                ho = usable if is_validation else np.zeros(t.size, dtype=bool)
            else:
                idx = np.flatnonzero(usable)
                cut = idx[0] + int(math.floor((1.0 - holdout) * idx.size))
                tr = usable.copy()
                tr[cut:] = False
                ho = usable & ~tr
                if tr.sum() < 5 or ho.sum() < 5:
                    raise InputError(f"{motion.name}: holdout {holdout:g} leaves fewer than 5 "
                                     "training or held-out samples")
            if test.mask is not None:
                # screening (damper.io.screening): the samples it flagged count neither in the fit
                # nor in the errors; the model is still simulated over all of them, and the
                # held-out split stays where it was in time. The acceleration of a sample within
                # half a derivative window of a flagged one is computed from flagged samples, so
                # it is left out too (numpy.gradient's fallback reaches one sample). A flagged
                # tail is already outside the split (above)
                usable_mask = reach_of_flagged(test.mask, window // 2 if window else 1)
                tr = tr & usable_mask
                ho = ho & usable_mask
                if not (is_validation or tr.sum() >= 5) or ((is_validation or not validate)
                                                          and ho.sum() < 5):
                    raise InputError(f"{motion.name}: the screening leaves fewer than 5 training "
                                     f"or held-out samples ({screening_of(test).brief()}; "
                                     "--keep-flagged keeps them)")
            motions.append(motion)
            forces.append(np.asarray(test.force, dtype=float))
            train.append(tr)
            held.append(ho)
        return cls(tuple(motions), tuple(forces), tuple(train), tuple(held), input_name,
                   None if validate else float(holdout), input_recorded=recorded)

    # -- derived quantities --------------------------------------------------------------------
    @property
    def names(self) -> list[str]:
        """Test labels."""
        return [m.name for m in self.motions]

    @property
    def input_unit(self) -> str:
        """``"V"`` or ``"A"``."""
        return "A" if self.input_name == "current" else "V"

    def levels(self) -> np.ndarray:
        """Distinct coil-input values over all tests (rounded to 1e-9; the least and the largest
        exact, so that :meth:`voltage_range` holds every input value: rounded, a command written
        with more digits, 1.9968512345 V, lay above its own range and the base model refused it)."""
        if self.source_levels is not None:
            return self.source_levels
        v = np.concatenate([m.v for m in self.motions])
        levels = np.unique(np.round(v, 9))
        if levels.size:
            levels[0] = v.min()
        if levels.size > 1:
            levels[-1] = v.max()
        return levels

    @property
    def input_varies_within_tests(self) -> bool:
        """Whether the coil input changes during some test."""
        return any(np.ptp(m.v) > 1e-12 for m in self.motions)

    def nodes(self) -> np.ndarray | None:
        """Voltage nodes for the base model's laws: ``None`` for one input level, the distinct
        levels when there are few (voltage steps between a few levels included: the laws are
        then PCHIP between the levels), else a uniform grid of four nodes between the 2.5th and
        97.5th percentiles of the input."""
        levels = self.levels()
        if levels.size <= 1:
            return None
        if levels.size <= _MAX_LEVEL_NODES:
            return levels
        # a grid over the bulk of the input: a measured command rings past its levels for a few
        # milliseconds after each switch (Dyke's records: 0-2.25 V commands read -0.44-2.71 V),
        # and nodes out there would be fitted on a handful of samples; the laws hold their end
        # values beyond the grid (:class:`~damper.models.voltage_laws.Tabulated`); ringing holds ~1 % of them
        if self.source_levels is None:
            v = np.concatenate([m.v for m in self.motions])
        else:  # a decimated copy keeps the full tests' nodes
            return self._source_nodes
        lo, hi = np.percentile(v, [_NODE_PERCENTILE, 100.0 - _NODE_PERCENTILE])
        if not hi > lo:
            lo, hi = levels[0], levels[-1]
        return np.linspace(lo, hi, _GRID_NODES)

    def voltage_range(self) -> tuple[float, float]:
        """Range of the base model's input: contains every input value and [0, 1]."""
        levels = self.levels()
        lo = min(0.0, float(levels[0]))
        hi = max(1.0, float(levels[-1]))
        # every value exactly, also where one level stands for values spread below its rounding
        # (the levels of a decimated copy are its source's, which contain its inputs)
        for m in self.motions:
            if m.v.size:
                lo, hi = min(lo, float(m.v.min())), max(hi, float(m.v.max()))
        return lo, hi

    def concat(self, arrays: Sequence[np.ndarray], which: str = "heldout") -> np.ndarray:
        """Concatenate per-test arrays over the ``which`` samples ("train", "heldout", "all").

        Parameters
        ----------
        arrays : Sequence[np.ndarray]
            One array per test, sample by sample.
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        """
        masks = self._masks(which)
        return np.concatenate([np.asarray(a)[k] for a, k in zip(arrays, masks)])

    def _masks(self, which: str):
        if which == "train":
            return self.train
        if which == "heldout":
            return self.heldout
        if which == "all":
            return tuple(a | b for a, b in zip(self.train, self.heldout))
        raise InputError(f"which: expected 'train', 'heldout' or 'all', got {which!r}")

    def measured(self, which: str = "heldout") -> np.ndarray:
        """Measured force [N] over the ``which`` samples.

        Parameters
        ----------
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        """
        return self.concat(self.forces, which)

    def signals(self, which: str = "heldout") -> dict[str, np.ndarray]:
        """The variables a residual is traced against, over the ``which`` samples (SI):
        displacement, velocity, acceleration, voltage (the coil input), voltage_rate, time (since
        the start of each test), and cycle (an integer label of each period of the dominant
        frequency of each test, so that the time dependence is read cycle by cycle).

        Parameters
        ----------
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        """
        rate = [np.gradient(m.v, m.t, edge_order=2) for m in self.motions]
        cycles = []
        for i, m in enumerate(self.motions):
            period = 1.0 / max(dominant_frequency(m.t, m.x), 1e-12)
            cycles.append(np.floor(m.elapsed / period) + 1e6 * i)
        return {
            "displacement": self.concat([m.x for m in self.motions], which),
            "velocity": self.concat([m.xdot for m in self.motions], which),
            "acceleration": self.concat([m.xddot for m in self.motions], which),
            "voltage": self.concat([m.v for m in self.motions], which),
            "voltage_rate": self.concat(rate, which),
            "time": self.concat([m.elapsed for m in self.motions], which),
            "cycle": self.concat(cycles, which),
        }

    def residual(self, model, which: str = "heldout") -> np.ndarray:
        """Measured minus predicted force [N] over the ``which`` samples.

        Parameters
        ----------
        model : object
            Anything with ``force(motion) -> ndarray`` (an
            :class:`~damper.diagnosis.augmented.AugmentedModel`), simulated over each whole test.
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        """
        return self.measured(which) - self.concat([model.force(m) for m in self.motions], which)

    def relative_error(self, model, which: str = "heldout",
                       forces: Sequence[np.ndarray] | None = None) -> float:
        """:math:`\\|F - \\hat F\\|_2 / \\|F\\|_2` of ``model`` over the ``which`` samples
        (:func:`damper.identification.metrics.relative_rms_error`).

        Parameters
        ----------
        model : object
            Anything with ``force(motion) -> ndarray``.
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        forces : sequence of ndarray, optional
            The model's force histories over every test, when they were simulated already (a
            full-rate simulation of a long recording costs about a second).

        Raises
        ------
        InputError
            The measured force is identically zero over those samples.
        """
        if forces is None:
            forces = [model.force(m) for m in self.motions]
        return relative_rms_error(self.measured(which), self.concat(forces, which))

    def force_rms(self, which: str = "train") -> float:
        """RMS of the measured force over the ``which`` samples [N].

        Parameters
        ----------
        which : str, optional
            Samples to use: ``"train"``, ``"heldout"`` or ``"all"``.
        """
        f = self.measured(which)
        return float(np.sqrt(np.mean(f ** 2)))
