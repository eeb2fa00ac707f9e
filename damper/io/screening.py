"""Screening of measured damper tests before anything is fitted to them.

Real recordings are dirty: a load cell saturates, a sensor freezes, a logger repeats or drops
samples, a test rig idles between runs, a velocity channel is filtered with a delay, a column is
in millimetres where metres were declared. :func:`screen` looks for each of these in a
:class:`~damper.io.data.DamperTest` and returns a :class:`Screening`: one :class:`Finding` per flaw
(what, which channel, where in time, how many samples) and a boolean ``usable`` mask (True:
the sample counts in fits and errors). The readers of :mod:`damper.io.data` and
:mod:`damper.io.dyke` screen every file they read (:func:`screened`), so the residual loop
(:mod:`damper.diagnosis`) and the identification (:mod:`damper.identification`) leave flagged
samples out of both the fit and the error unless the user keeps them (``--keep-flagged``).

Checks (no threshold is in physical units except the plausibility ranges of the last one):

``nan``
    Missing values (NaN cells, dropouts). Repaired by :func:`repair_samples` before the test is
    built: an input channel (displacement, velocity, coil input) is interpolated linearly in
    time so the model can still be simulated through the dropout; the samples are excluded.
``time``
    Repeated or backward time stamps (a logger glitch or concatenated files): the offending
    samples are dropped (:func:`repair_samples`), the step after them excluded. A backward step
    followed by :data:`RESTART_ROWS` rows or more on a clock of their own is said as a clock
    restart (a second recording appended): :func:`damper.io.reader.read_tests`, hence the
    commands, read each recording as a test of its own (:func:`clock_restarts`).
``rounded``
    Time stamps written with too few digits: the steps of a uniformly sampled test vary by
    more than :data:`ROUNDED_STEP_SPREAD` (the Dyke files: 0.1-ms stamps on a 0.333-ms step,
    steps of 0.3 and 0.4 ms), and every stamp lies within half its decimal resolution of one
    uniform grid (:func:`rounded_time_grid`). The grid is restored by :func:`repair_samples`
    (a finding, no sample excluded): the model steps over the true intervals and the
    derivatives (acceleration, the velocity check) are not taken over ±15 % jitter. Stamps off
    the grid by more than their rounding are a real irregular sampling and are kept as read.
    A clock coarser than the sampling step (stamps repeated as such a clock repeats them: a 1-ms
    clock at 3 kHz) is restored the same way, every row kept (:func:`coarse_time_grid`).
``held``
    One acquisition written into two or more consecutive time slots (a logger that missed a
    sample period and repeated a reading): the displacement *and* the force repeat to within
    :data:`HELD_TOLERANCE` of their ranges while the displacement moves on both sides, in one
    direction, by at least :data:`HELD_STEPS` of its resolution per sample (the smallest gap
    between two of its values: a quantised channel at a reversal or on a slow plateau repeats
    too, but not in mid-stroke on both channels at once). Which slot the reading belongs to is unknown, so every slot of the
    run is treated as missing (:func:`repair_samples`): the input channels are interpolated
    through it and the samples excluded. A velocity the logger differentiates from such a
    displacement jumps to twice its value and then to zero there: it is interpolated too.
``spike``
    Isolated samples of a measured channel (force, displacement, velocity) that jump away from
    their neighbours and back (a logger's or amplifier's glitch): runs of at most
    :data:`SPIKE_MAX_RUN` samples on one side of the median of the samples within
    :data:`SPIKE_REACH` of them, by more than :data:`SPIKE_FACTOR` times the channel's local step
    (and the step of the line that bridges the run) and :data:`SPIKE_SHARE_OF_RANGE` of its
    range (:func:`spike_samples`; a step, a ramp or a reversal leaves the median with the
    sample). Treated as missing (:func:`repair_samples`):
    interpolated, not fitted. More than :data:`SPIKE_MAX_SHARE` of the samples are something the
    channel does, not glitches: reported and left as read. Within a dominant period of a stuck,
    clipped or frozen span or a lurch they are the fault's: excluded, not reported apart.
``lost``
    A single sample missing from a uniform grid (a logger that missed a sample period and wrote
    no row for it: one step of two, :func:`lost_slots`). Left as read, the double step spread the
    steps: rounded stamps were not restored and every derivative taken on the median step was
    off (11 % on a Dyke file with one row deleted). The slot is put back on the grid
    (:func:`repair_samples`), the input channels interpolated through it like a held reading,
    and the sample excluded; no settling follows it.
``gap``
    A time step longer than :data:`GAP_FACTOR` times the median step: the motion inside it is
    unknown.
``stuck`` / ``clipped``
    A channel repeating exactly the same value for longer than the channel's own repeats
    explain (a frozen or saturated sensor); ``clipped`` when the value piles up at the channel's
    extreme (many more samples at the extreme value than at the levels just inside it).
``frozen``
    The displacement stuck while the force changes (the motion the force answers is unknown).
``idle``
    Spans with no motion (the displacement moves less than :data:`IDLE_FRACTION` of the
    test's stroke over a quarter of the dominant period): the rig waiting between runs.
``difference``
    A velocity column that is the logger's one-sided difference of the displacement column
    (``(x[i] - x[i-1]) / dt`` or ``(x[i+1] - x[i]) / dt`` to :data:`DIFFERENCE_TOLERANCE` of the
    peak velocity at all but :data:`DIFFERENCE_EXCEPTIONS` of the usable samples): not a
    measurement but a derivative half a step late (or early), which delays the model's velocity
    input against its displacement by half a sample (10 ms at 50 Hz). Replaced by the central
    difference (:func:`repair_samples`; a finding, no sample excluded).
``velocity``
    A measured velocity that disagrees with the derivative of the displacement: a wrong gain
    (units), a time offset (estimated by cross-correlation), or spans where the two depart.
``offset``
    The lag between the force and the motion channels (cross-correlation of the force with
    the velocity), reported in :attr:`Screening.estimates`; a finding when the velocity
    channel is itself offset from the displacement.
``excursion``
    A fault's lurch: next to a stuck, frozen or clipped channel or a gap (within one dominant
    period), the velocity runs beyond :data:`EXCURSION_FACTOR` times the test's own 99.5th
    percentile of the absolute velocity (a rig losing control before it freezes). The whole flank, out to
    where the velocity is back inside that percentile, is an unusable input span. Far from a
    fault a fast stretch is data (an earthquake-like test has rare pulses): it is not flagged.
``island``
    A usable stretch shorter than one dominant period between two flagged spans, or between one
    and the test's start or end, next to a fault of the motion (not where only the force was
    flagged): excluded too.
``units``
    Amplitudes, peak velocities, forces or coil inputs outside what any MR damper test produces
    (e.g. a displacement in mm declared as m, a current in mA declared as A); reported, not
    excluded (the whole test would go).
``polarity``
    The force does net negative work on the motion: ∫ F·ẋ dt over the usable samples (ẋ the
    displacement's derivative) is below :data:`POLARITY_SHARE` times -∫ |F·ẋ| dt. A damper,
    passive or semi-active, only dissipates (its force opposes the velocity on average; an
    elastic part adds no work over a cycle), so the force channel's sign is inverted against
    the motion (a load cell read tension-positive against a compression-positive stroke, or the
    other way round). Reported, not excluded; the command line refuses such a file.

Where an *input* channel (displacement, velocity, coil input) is unusable the model cannot be
simulated through it faithfully. The span is kept in the test (interpolated where values are
missing; a frozen displacement is a valid, if wrong, motion) so the test stays one continuous
history and a held-out split by time keeps its meaning; the span is excluded and so is the
*settling* after it, up to the first displacement reversal (the same rule the residual loop
applies at the start of every test): a Bouc-Wen-type model forgets its hysteretic state within
one reversal, so after it the prediction no longer depends on the unknown motion. Where only
the force is bad (stuck, clipped, missing) the model is simulated as usual and only those
samples are excluded.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from benchmark.foundation.channel_runs import runs as _runs, stuck_spans
from benchmark.foundation.errors import InputError

__all__ = ["Finding", "Screening", "screen", "screened", "repair_samples", "keep_flagged", "next_reversal",
           "screening_of", "screening_summary", "steady_level", "STEADY_SHARE", "STEADY_FLOOR", "screening_key", "screening_lines", "units_line", "rounded_time_grid", "ROUNDED_STEP_SPREAD", "lost_slots", "LOST_MAX_SHARE", "filled_samples", "coarse_time_grid", "COARSE_MIN_REPEATS", "COARSE_MISSING_SHARE", "band_edge", "BAND_EDGE_SHARE", "dominant_frequency", "stroke_rate", "DRIFT_SHARE", "stuck_spans", "GAP_FACTOR", "IDLE_FRACTION", "PLAUSIBLE", "EXCURSION_FACTOR",
           "POLARITY_SHARE", "net_work", "held_samples", "held_runs", "HELD_TOLERANCE", "HELD_STEPS", "HELD_MAX_SLOTS", "HELD_MAX_SHARE",
           "one_sided_difference", "DIFFERENCE_TOLERANCE", "DIFFERENCE_EXCEPTIONS", "velocity_scale",
           "DEAD_VELOCITY_SHARE", "VELOCITY_GAIN_TOLERANCE", "finding_lines", "GROUPED_SPANS", "CLIPPED_FORCE_SHARE",
           "clipped_force_share", "derivative_window", "smoothed_derivative", "spike_samples",
           "SPIKE_REACH", "SPIKE_MAX_RUN", "SPIKE_FACTOR", "SPIKE_SHARE_OF_RANGE", "SPIKE_MAX_SHARE",
           "RESTART_ROWS", "clock_restarts"]

#: ``held``: two samples are one reading when both the displacement and the force agree to this
#: share of their ranges (a 30-bit converter's step; the loggers' own arithmetic leaves 1e-13).
HELD_TOLERANCE = 1e-9
#: ``held``: the displacement must move by this many of its resolution steps per sample on both
#: sides of the repeat (a staircase of a slow, quantised stroke moves by one).
HELD_STEPS = 3.0
#: ``held``: the longest run of one reading that counts as missed sample periods (the LabControl
#: UTFPR files hold 2-4); a longer one is a pause of the rig.
HELD_MAX_SLOTS = 4
#: ``held``: held runs over more than this share of the samples are the file's make-up (every
#: reading written twice: a file resampled by repetition, half the samples), reported once and
#: left as read (the LabControl UTFPR files miss up to 5 % of their sample periods).
HELD_MAX_SHARE = 0.2
#: ``difference``: a velocity column within this share of its peak of a one-sided difference of
#: the displacement at every usable sample is that difference (the UTFSM files, written to a few
#: digits, leave up to 5e-6; a velocity sensor or a filtered derivative departs by 1e-3 and more).
DIFFERENCE_TOLERANCE = 1e-4
#: ``difference``: share of the sample pairs that may depart from it (a dropped row, a glitch).
DIFFERENCE_EXCEPTIONS = 0.005
#: A time step this many times the median step is a gap.
GAP_FACTOR = 2.5
#: No motion: the displacement moves less than this fraction of the test's stroke.
IDLE_FRACTION = 0.02
#: Plausible ranges of an MR damper test (SI): from bench-top dampers (mm strokes, tens of N)
#: to the large-scale 20-t devices (±0.6 m, 2 MN); a value outside them is a unit error.
PLAUSIBLE = {"amplitude": (2e-5, 1.0), "peak_velocity": (1e-5, 5.0), "peak_force": (0.5, 5e6),
             "sample_rate": (5.0, 1e6),
             # the coil input: drivers of MR dampers command up to 24 V or a few amperes (the
             # UTFSM damper 0-1 A, the Dyke damper's command -0.44-2.7 V); mV or mA read as V or A
             # lands far above these
             "peak_voltage": (0.0, 60.0), "peak_current": (0.0, 25.0)}
#: A velocity beyond this many times the test's 99.5th percentile of |velocity|, next to a fault,
#: is the fault's lurch (a Gaussian motion exceeds 2 x its 99.5th percentile, 5.6 sigma, with
#: probability 2e-8 per sample; a sine never does).
EXCURSION_FACTOR = 2.0
#: ``polarity``: the force's net work on the motion, as a share of its absolute work, below minus
#: this (a damper's is positive: the 30 UTFSM files and the Dyke recording give 0.988-1.000, the
#: virtual laboratory 0.71-0.995; a spring-dominated loop nears 0 but does not go negative over
#: cycles).
POLARITY_SHARE = 0.2
#: ``spike``: a sample is compared with the median of the samples within this reach each side
#: (a run of up to this many samples on one side of it leaves the median with the others).
SPIKE_REACH = 3
#: ``spike``: runs of at most this many samples (a logger's glitch; a longer excursion is a fault
#: or motion, the other checks' matter).
SPIKE_MAX_RUN = 3
#: ``spike``: the departure from that median must exceed this many times the channel's local step
#: (the median |difference| of the samples around it, at least the channel's resolution): a
#: coarsely sampled peak departs by about one step, a glitch by tens to hundreds.
SPIKE_FACTOR = 10.0
#: ``spike``: ... and this share of the channel's range (0.5-99.5th percentile): smaller glitches
#: change no fit.
SPIKE_SHARE_OF_RANGE = 0.05
#: ``spike``: more spikes than this share of the samples are no glitches but something the
#: channel does (a knock at every reversal): reported, left as read.
SPIKE_MAX_SHARE = 0.002
#: ``time``: a backward step followed by at least this many rows on a clock of their own is a
#: second recording appended, said as such.
RESTART_ROWS = 100
#: ``rounded``: a clock coarser than the sampling (:func:`coarse_time_grid`) shows at least this
#: many repeated stamps ...
COARSE_MIN_REPEATS = 3
#: ... and at most this share of its stamps missing (NaN: their rows get their slots' times).
COARSE_MISSING_SHARE = 0.01
#: ``lost``: at most this share of a test's steps may be a lost sample's double step for the
#: uniform grid to be restored with the lost slots (:func:`lost_slots`; more is irregular sampling).
LOST_MAX_SHARE = 0.01
#: Channels screened for stuck values (the coil input is a command: constant runs are normal).
_MEASURED = ("force", "displacement", "velocity")
#: A velocity column missing in more than this share of its samples is dropped (a dead channel;
#: the displacement's derivative drives the model, as for a file without one).
DEAD_VELOCITY_SHARE = 0.5
#: A velocity column whose scale against the displacement's derivative is off 1 by more than this
#: (or negative) is replaced by the central difference: a unit, gain or sign error. The measured
#: files sit within 1.1 % (UTFSM 1.0006-1.0105, docs/diagnosis.md)
VELOCITY_GAIN_TOLERANCE = 0.1
_INPUTS = ("displacement", "velocity", "voltage", "current")
#: Findings whose samples :func:`repair_samples` interpolates over a few slots (no fault of the
#: rig: no settling after them, and no measurement to keep with ``--keep-flagged``).
_INTERPOLATED = ("held", "spike", "lost")


@dataclass(frozen=True)
class Finding:
    """One flaw found by :func:`screen`.

    Attributes
    ----------
    kind : str
        ``nan``, ``time``, ``duplicate``, ``rounded``, ``lost``, ``held``, ``spike``, ``difference``, ``gap``,
        ``stuck``, ``clipped``,
        ``frozen``, ``idle``, ``velocity``, ``offset``, ``units`` or ``polarity``.
    channel : str
        The channel (``force``, ``displacement``, ``velocity``, ``voltage``, ``current``,
        ``time``).
    t_start, t_end : float
        Where [s] (the whole test for a global finding).
    n_samples : int
        Samples concerned (0 for an estimate that concerns no sample).
    message : str
        One line for the report.
    excluded : bool
        Whether these samples are left out of fits and errors.
    """

    kind: str
    channel: str
    t_start: float
    t_end: float
    n_samples: int
    message: str
    excluded: bool = True

    def line(self, kept: bool = False) -> str:
        """``kind (channel) at t0-t1 s, n sample(s): message [excluded ...]`` (``kept``: the
        flagged samples were kept by the user).

        Parameters
        ----------
        kept : bool
            The user kept the flagged samples (``--keep-flagged``).
        """
        where = (f"{self.t_start:.4g} s" if self.t_end == self.t_start
                 else f"{self.t_start:.4g}-{self.t_end:.4g} s")
        tail = "excluded from fit and error" if self.excluded else "reported only"
        if kept and self.excluded and self.kind != "nan":
            tail = "kept in fit and error (--keep-flagged)"
        return (f"{self.kind} ({self.channel}) at {where}, {self.n_samples} sample(s): "
                f"{self.message} [{tail}]")

    def to_json(self) -> dict:
        """JSON-ready dict."""
        return dataclasses.asdict(self)


#: Share of a test's samples left out as a clipped force above which the test is refused: its
#: force peaks are not measured, and a fit on the rest extrapolates past the clip level (a
#: probe's UTFSM test clipped at 1200 of 1460 N lost 62 % of its samples; the model fitted on
#: the rest printed a 7 % fit error and erred by 54 % over the whole record).
CLIPPED_FORCE_SHARE = 0.5


def clipped_force_share(test: Any) -> float:
    """Share of ``test``'s samples left out of fits because its force is clipped there.

    Parameters
    ----------
    test : DamperTest
        A screened test (its ``usable`` mask and screening).
    """
    usable = np.asarray(test.usable, dtype=bool)
    time = np.asarray(test.time, dtype=float)
    clipped = np.zeros(usable.size, dtype=bool)
    for f in screening_of(test).findings:
        if f.kind == "clipped" and f.channel == "force" and f.excluded:
            clipped |= (time >= f.t_start) & (time <= f.t_end)
    return float(np.count_nonzero(clipped & ~usable)) / max(1, usable.size)


#: More spans of one kind and channel than this are said in one line (a clipped force had printed
#: 22 lines, one per clipped peak).
GROUPED_SPANS = 3


def finding_lines(findings: Sequence[Finding], kept: bool = False) -> list[str]:
    """The findings as report lines, one per finding, except that more than
    :data:`GROUPED_SPANS` of one kind and channel make one line (count, samples, time range,
    the first one's message).

    Parameters
    ----------
    findings : sequence of Finding
        A test's findings.
    kept : bool
        The user kept the flagged samples (``--keep-flagged``).
    """
    groups: dict[tuple[str, str], list[Finding]] = {}
    for f in findings:
        groups.setdefault((f.kind, f.channel), []).append(f)
    out = []
    for (kind, channel), items in groups.items():
        if len(items) <= GROUPED_SPANS:
            out += [f.line(kept=kept) for f in items]
            continue
        first = items[0]
        tail = first.line(kept=kept).rsplit(" [", 1)[-1]
        out.append(f"{kind} ({channel}) in {len(items)} spans, {sum(f.n_samples for f in items)} samples between "
                   f"{min(f.t_start for f in items):.4g} and {max(f.t_end for f in items):.4g} s; the first: "
                   f"{first.message} [{tail}")
    return out


@dataclass(frozen=True)
class Screening:
    """Outcome of :func:`screen`: the findings and the samples usable for fits and errors.

    Attributes
    ----------
    findings : tuple of Finding
    usable : ndarray of bool
        True where the sample counts in fits and errors (the flagged spans and the settling
        after unusable input spans are False).
    estimates : dict
        Quantities estimated on the way (force-velocity lag [s], velocity gain and lag, ...).
    name : str
        The test's label.
    """

    findings: tuple
    usable: np.ndarray = field(repr=False)
    estimates: dict = field(default_factory=dict)
    name: str = ""

    @property
    def n_excluded(self) -> int:
        """Samples left out of fits and errors."""
        return int(np.size(self.usable) - np.count_nonzero(self.usable))

    @property
    def clean(self) -> bool:
        """No finding."""
        return not self.findings

    def lines(self) -> list[str]:
        """One line per finding, then the count of excluded samples (report text)."""
        head = self.name or "test"
        if not self.findings:
            return [f"{head}: screening found nothing"]
        out = [f"{head}: {line}" for line in finding_lines(self.findings)]
        out.append(f"{head}: {self.n_excluded} of {np.size(self.usable)} samples excluded "
                   "from fit and error")
        return out

    def brief(self) -> str:
        """The findings in a few words, for a one-line error: each excluding kind with its spans
        and samples (largest first), then every ``units`` finding's text.

        Examples: ``"stuck force: 12 spans, 1504 samples; island: 3 spans, 840 samples"``,
        ``"units: sample rate 3.005 Hz is outside the plausible ... (wrong unit?)"``.
        """
        groups: dict = {}
        for f in self.findings:
            if f.excluded and f.kind != "units":
                key = f"{f.kind} {f.channel}" if f.kind in ("stuck", "clipped", "nan") else f.kind
                spans, samples = groups.get(key, (0, 0))
                groups[key] = (spans + 1, samples + f.n_samples)
        parts = [f"{k}: {n} span{'s' if n != 1 else ''}, {m} samples"
                 for k, (n, m) in sorted(groups.items(), key=lambda kv: -kv[1][1])]
        parts += [f"units: {f.message}" for f in self.findings if f.kind == "units"]
        return "; ".join(parts) if parts else "nothing found"

    def units_problem(self) -> str | None:
        """The ``units`` findings' text, joined (None when every amplitude is plausible)."""
        texts = [f"{f.channel}: {f.message}" for f in self.findings if f.kind == "units"]
        return "; ".join(texts) or None

    def polarity_problem(self) -> str | None:
        """The ``polarity`` finding's text (None when the force dissipates, as a damper's does)."""
        texts = [f.message for f in self.findings if f.kind == "polarity"]
        return "; ".join(texts) or None

    def estimate_line(self) -> str:
        """The estimated lags and gain in one line (empty when none was estimated)."""
        e = self.estimates
        parts = []
        if "force_velocity_lag_s" in e:
            parts.append(f"force lags the motion's velocity by {1e3 * e['force_velocity_lag_s']:.3g} ms "
                         f"(cross-correlation peak {e.get('force_velocity_correlation', float('nan')):.3f})")
        if "velocity_lag_s" in e:
            parts.append(f"velocity channel: {1e3 * e['velocity_lag_s']:.3g} ms behind d(x)/dt, gain "
                         f"{e.get('velocity_gain', float('nan')):.4g}")
        return "; ".join(parts)

    def to_json(self) -> dict:
        """``{"name", "n_samples", "n_excluded", "findings": [...], "estimates": {...}}``."""
        return {"name": self.name, "n_samples": int(np.size(self.usable)),
                "n_excluded": self.n_excluded,
                "findings": [f.to_json() for f in self.findings],
                "estimates": {k: (float(v) if isinstance(v, (int, float, np.floating)) else v)
                              for k, v in self.estimates.items()}}


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------
#: Spectral lines below this share of a motion's stroke rate (:func:`dominant_frequency`) are the
#: drift of its mean position, not its strokes: a one-sided sine sweep's step from rest to its mean
#: position and back, and that step's first harmonics. The recordings the project reads have their
#: peak at 0.13 (the Dyke damper's random motion, ``ranran_50``: 0.97 Hz against 7.7 strokes/s) to
#: 3.5 times their stroke rate; the UTFSM validation sweeps at 0.003 (docs/diagnosis.md).
DRIFT_SHARE = 0.1


def stroke_rate(t: np.ndarray, x: np.ndarray, hysteresis: float = 0.05) -> float:
    """Strokes per second [Hz] of ``x``: half its crossings of its median, each counted once it
    has passed by ``hysteresis`` of the stroke beyond it (a Schmitt trigger: noise does not count).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s].
    x : np.ndarray
        The motion at ``t``.
    hysteresis : float, optional
        Share of the stroke (the 0.5-99.5 percentile range) on each side of the median.
    """
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    lo, mid, hi = np.percentile(x, [0.5, 50.0, 99.5]) if x.size else (0.0, 0.0, 0.0)
    band = hysteresis * float(hi - lo)
    if not (span > 0.0 and band > 0.0):
        return 0.0
    side = np.sign(np.where(np.abs(x - mid) > band, x - mid, 0.0))
    side = side[side != 0.0]
    return float(np.count_nonzero(np.diff(side))) / (2.0 * span)


def dominant_frequency(t: np.ndarray, x: np.ndarray) -> float:
    """Frequency [Hz] of the largest spectral peak of ``x`` (Hann window, the mean excluded).

    Lines below :data:`DRIFT_SHARE` of the motion's :func:`stroke_rate` are left out: they are the
    drift of its mean position (a one-sided sine sweep's, whose peak would otherwise be the sweep's
    own length), not its strokes. A signal too short (fewer than 8 samples) or flat to have a peak
    gets one cycle over its span.

    Parameters
    ----------
    t : np.ndarray
        Uniform sample times [s].
    x : np.ndarray
        The signal at ``t`` (a displacement, here).
    """
    n = t.size
    span = float(t[-1] - t[0])
    dt = span / max(n - 1, 1)
    if n < 8 or not np.ptp(x) > 0:
        return 1.0 / max(span, dt, 1e-300)
    spectrum = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(n)))
    freqs = np.fft.rfftfreq(n, dt)
    first = max(1, int(np.searchsorted(freqs, DRIFT_SHARE * stroke_rate(t, x))))
    if first >= freqs.size:
        first = 1
    return float(freqs[first + int(np.argmax(spectrum[first:]))])


#: Share of a signal's variance below its band edge (:func:`band_edge`).
BAND_EDGE_SHARE = 0.95


def band_edge(t: np.ndarray, v: np.ndarray, share: float = BAND_EDGE_SHARE) -> float:
    """Frequency [Hz] below which ``share`` of the variance of ``v`` lies (its band edge).

    Parameters
    ----------
    t : np.ndarray
        Uniform sample times [s].
    v : np.ndarray
        The signal at ``t``.
    share : float, optional
        Share of the variance (0-1).
    """
    n = t.size
    if n < 4:
        return 0.0
    dt = (t[-1] - t[0]) / (n - 1)
    power = np.abs(np.fft.rfft((v - v.mean()) * np.hanning(n)))[1:] ** 2
    total = float(power.sum())
    if not total > 0.0:
        return 0.0
    k = int(np.searchsorted(np.cumsum(power), share * total))
    return float(np.fft.rfftfreq(n, dt)[1 + min(k, power.size - 1)])


def spike_samples(values: np.ndarray) -> np.ndarray:
    """The samples of one channel that are spikes (the module docstring's ``spike``).

    Parameters
    ----------
    values : np.ndarray
        The channel's samples, NaN where missing (never a spike).

    Returns
    -------
    np.ndarray of bool
    """
    y = np.asarray(values, dtype=float)
    n = y.size
    out = np.zeros(n, dtype=bool)
    finite = np.isfinite(y)
    if n < 2 * SPIKE_REACH + 3 or finite.sum() < 2 * SPIKE_REACH + 3:
        return out
    idx = np.arange(n)
    yf = y if finite.all() else np.interp(idx, idx[finite], y[finite])
    lo, hi = np.percentile(yf, [0.5, 99.5])
    if not hi > lo:
        return out
    median = np.median(sliding_window_view(np.pad(yf, SPIKE_REACH, mode="edge"), 2 * SPIKE_REACH + 1), axis=1)
    departure = yf - median
    candidate = finite & (np.abs(departure) > SPIKE_SHARE_OF_RANGE * (hi - lo))
    if not candidate.any():
        return out
    levels = np.unique(yf)
    resolution = float(np.min(np.diff(levels))) if levels.size > 1 else 0.0
    steps = np.abs(np.diff(yf))
    reach = 4 * SPIKE_REACH
    for sign in (1.0, -1.0):
        for a, b in _runs(candidate & (sign * departure > 0)):
            # a coarsely sampled motion's own samples beside a spike depart from the median too
            # (on the same side): the run is trimmed to its core below
            if b - a > SPIKE_MAX_RUN + 2 * SPIKE_REACH:
                continue
            # the local step from the differences that do not touch the run (those are the spike's)
            local = np.concatenate((steps[max(a - 1 - reach, 0):max(a - 1, 0)], steps[b:b + reach]))
            step = max(float(np.median(local)) if local.size else 0.0, resolution)
            core = a + np.flatnonzero(sign * departure[a:b] > SPIKE_FACTOR * step)
            if core.size == 0 or core.size > SPIKE_MAX_RUN or core[-1] - core[0] + 1 != core.size:
                continue
            c, d = int(core[0]), int(core[-1]) + 1
            # and at least the step of the line that bridges it: a sharp but continuous peak (a
            # force transient of a random test) lies between neighbours that differ as much
            bridge = abs(yf[min(d, n - 1)] - yf[max(c - 1, 0)]) / (d - c + 1)
            if float(np.min(np.abs(departure[c:d]))) > SPIKE_FACTOR * max(step, bridge):
                out[c:d] = True
    return out


def clock_restarts(time: np.ndarray, channels: dict | None = None) -> list[int]:
    """The rows where a file's clock restarts: a second recording appended to the first.

    A row ``i`` is one when the time steps back there and the :data:`RESTART_ROWS` rows from it
    run on a clock of their own: strictly increasing and all before the time already reached
    (a stale stamp rejoins the file's clock at the next row), and they are not copies of earlier
    rows (a block written again: :func:`repair_samples` drops the copies with nothing lost).

    Parameters
    ----------
    time : np.ndarray
        The file's time column as read [s].
    channels : dict of str to np.ndarray, optional
        The other columns, to tell a block written again from a new recording.
    """
    t = np.asarray(time, dtype=float)
    cuts: list[int] = []
    reached = np.fmax.accumulate(t) if t.size else t
    for i in (np.flatnonzero(np.diff(t) < 0.0) + 1).tolist():
        run = t[i:i + RESTART_ROWS]
        if run.size < RESTART_ROWS or not (np.all(np.diff(run) > 0.0) and run[-1] < reached[i - 1]):
            continue
        if channels:
            earlier = {float(v): k for k, v in enumerate(t[:i])}
            same = [earlier.get(float(v)) for v in run[:5]]
            if all(j is not None for j in same) and all(
                    np.array_equal(np.asarray(c, dtype=float)[i:i + 5], np.asarray(c, dtype=float)[same], equal_nan=True)
                    for c in channels.values() if c is not None):
                continue  # the rows again, not a new recording
        cuts.append(int(i))
    return cuts


def derivative_window(t: np.ndarray, period: float, edge: float = 0.0, per_period: float = 40.0,
                      jitter: float = 0.5) -> int:
    """Samples (odd, at least 5) in the Savitzky-Golay window of :func:`smoothed_derivative`.

    The window spans ``1/per_period`` of ``period``, or of the period at half the velocity's band
    edge ``edge`` when that is shorter (a broadband motion's dominant period is its slowest
    drift: over it the derivative would smooth away the band the channels measure), and at most
    a quarter of the samples. It is 0, where the derivative falls back to :func:`numpy.gradient`
    (reach one sample each side), for fewer than 7 samples, for steps that spread by more than
    ``jitter`` times the median step, and for a window as long as the test.

    The screening differentiates the displacement over 1/40 of the period (to compare it with a
    velocity channel, as little smoothing as the noise allows); the diagnosis differentiates the
    velocity over 1/20 on its restored, uniform time grid (``jitter=1e-6``; the acceleration of
    the ``inertia`` term, :func:`damper.diagnosis.dataset.acceleration_window`).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s].
    period : float
        The motion's dominant period [s] (``inf`` or 0 when it has none).
    edge : float
        The velocity's band edge [Hz] (:func:`band_edge`; 0: none).
    per_period : float
        Windows per period.
    jitter : float
        The largest spread of the time steps, as a share of the median step, still taken as uniform.
    """
    t = np.asarray(t, dtype=float)
    if t.size < 7:
        return 0
    steps = np.diff(t)
    dt = float(np.median(steps))
    if not dt > 0.0 or np.ptp(steps) > jitter * dt:
        return 0
    if edge > 0.0:
        period = min(period, 2.0 / edge)
    window = int(round(period / (per_period * dt))) | 1 if 0.0 < period < math.inf else 5
    window = max(5, min(window, (t.size // 4) | 1))
    return 0 if window >= t.size else window


def smoothed_derivative(t: np.ndarray, y: np.ndarray, window: int = 0) -> np.ndarray:
    """d(y)/dt: the Savitzky-Golay derivative (order 2) over ``window`` samples
    (:func:`derivative_window`), or :func:`numpy.gradient` (second order where there are three
    samples or more) for ``window = 0``.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], uniform where ``window > 0``.
    y : np.ndarray
        The signal at ``t``.
    window : int
        Samples in the window (odd, at least 5), or 0.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if window == 0:
        return np.gradient(y, t, edge_order=2 if t.size > 2 else 1)
    # scipy.signal (and the scipy.stats it pulls in) only where a test is differentiated: importing
    # it with this module cost every building process 0.35 s and ~26 MB (the simulator reaches
    # this module through damper.models.response)
    from scipy.signal import savgol_filter

    # the mean step: stamps within the window rule's jitter but rounded to a coarse digit step
    # unevenly (0.3 and 0.4 ms on a 0.333-ms grid) have a median step 10 % off the true one
    return savgol_filter(y, window, 2, deriv=1, delta=float((t[-1] - t[0]) / (t.size - 1)), mode="interp")


def _derivative(t: np.ndarray, x: np.ndarray, period: float, edge: float = 0.0) -> np.ndarray:
    """The screening's d(x)/dt: over 1/40 of the period (:func:`derivative_window`)."""
    return smoothed_derivative(t, x, derivative_window(t, period, edge))


def next_reversal(x: np.ndarray, start: int, hysteresis: float = 0.25) -> int:
    """Index of the first displacement reversal at or after ``start`` (``x.size`` if none).

    A reversal counts once the displacement has come back by ``hysteresis`` of the stroke of
    the rest of the test from its running extreme (a Schmitt trigger, insensitive to noise).

    Parameters
    ----------
    x : np.ndarray
        Displacement [m].
    start : int
        First sample looked at.
    hysteresis : float, optional
        Return, as a fraction of the rest's stroke, that makes a reversal.
    """
    rest = x[start:]
    if rest.size < 3:
        return x.size
    stroke = float(np.ptp(rest))
    if not stroke > 0:
        return x.size
    moved = np.flatnonzero(np.abs(rest - rest[0]) > 0.05 * stroke)
    if moved.size == 0:
        return x.size
    y = rest if rest[moved[0]] > rest[0] else -rest
    back = np.flatnonzero(np.maximum.accumulate(y) - y > hysteresis * stroke)
    if back.size == 0:
        return x.size
    return start + int(np.argmax(y[:back[0] + 1]))


def _delay(a: np.ndarray, b: np.ndarray, max_lag: int) -> tuple[float, float, float]:
    """Delay (in samples, fractional), gain and correlation of ``a`` ≈ g b(t - d).

    The integer part from the cross-correlation peak; the fraction by least squares on the
    shifted ``b`` and its derivative (:math:`b(t-\\delta) \\approx b - \\delta b'`): the
    correlation of a smooth signal is too flat near its peak to place it to a sample.
    """
    lag, corr = _lag(a, b, max_lag)
    frac, gain = 0.0, 1.0
    tried = {lag}
    while True:  # Gauss-Newton on the delay, a sample at a time at most
        shifted = np.roll(b, lag)
        lo, hi = abs(lag) + 1, a.size - abs(lag) - 1
        if hi - lo < 8:
            return float(lag), gain, corr
        db = 0.5 * (shifted[lo + 1:hi + 1] - shifted[lo - 1:hi - 1])
        coef, *_ = np.linalg.lstsq(np.column_stack([shifted[lo:hi], db]), a[lo:hi], rcond=None)
        gain = float(coef[0])
        frac = float(-coef[1] / coef[0]) if coef[0] != 0 else 0.0
        step = int(np.sign(frac))
        # a delay of half a sample flips between two lags: stay with the lag the fraction was
        # computed at (the fraction and its lag must belong together)
        if abs(frac) <= 0.5 or abs(lag + step) > max_lag or lag + step in tried:
            break
        lag += step
        tried.add(lag)
    return lag + float(np.clip(frac, -1.0, 1.0)), gain, corr


def _within(mask: np.ndarray, reach: int) -> np.ndarray:
    """True where a True sample of ``mask`` lies within ``reach`` samples (either side)."""
    count = np.concatenate(([0], np.cumsum(mask, dtype=np.int64)))
    idx = np.arange(mask.size)
    return count[np.minimum(idx + reach + 1, mask.size)] - count[np.maximum(idx - reach, 0)] > 0


def _clean_stretch(ok: np.ndarray, trim: int) -> slice | None:
    """The longest run of ``ok`` samples, less ``trim`` samples at each end that borders a flagged
    one; None when every sample is ok (the whole test is the stretch) or no run of at least half
    the test is left (then the estimates use every unflagged sample, as before)."""
    if ok.all() or not ok.any():
        return None
    a, b = max(_runs(ok), key=lambda r: r[1] - r[0])
    a, b = (a + trim if a > 0 else a), (b - trim if b < ok.size else b)
    return slice(a, b) if b - a >= 0.5 * ok.size else None


def _lag(a: np.ndarray, b: np.ndarray, max_lag: int) -> tuple[int, float]:
    """Lag (samples, ``a`` delayed by it relative to ``b``) and peak normalised correlation."""
    a = a - a.mean()
    b = b - b.mean()
    na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if not (na > 0 and nb > 0):
        return 0, 0.0
    n = a.size
    # a lag of more than half the signal leaves too little overlap to average (and none at n)
    max_lag = min(int(max_lag), n // 2)
    size = 1 << int(math.ceil(math.log2(2 * n)))
    cc = np.fft.irfft(np.fft.rfft(a, size) * np.conj(np.fft.rfft(b, size)), size)
    lags = np.r_[np.arange(0, max_lag + 1), np.arange(-max_lag, 0)]
    # unbiased: each lag's sum over its overlap only (a smooth signal's correlation is flat near
    # its peak, and the shrinking overlap would pull the peak towards lag 0)
    values = cc[lags % size] * n / (n - np.abs(lags))
    k = int(np.argmax(values))
    return int(lags[k]), float(values[k] / (na * nb))


# ---------------------------------------------------------------------------------------------
# repair (readers): NaN and time stamps
# ---------------------------------------------------------------------------------------------
def _where(lines, i: int, label: str) -> str:
    return f"{label}:{lines[i]}" if lines is not None else f"{label}: sample {i}"


#: Relative spread of the time steps ((max - min) / median) above which stamps are checked for
#: rounding (a uniform grid written with enough digits spreads by ~1e-12).
ROUNDED_STEP_SPREAD = 0.01


def _last_digit(t: np.ndarray) -> np.ndarray:
    """The decimal resolution of each stamp [s]: the coarsest ``10**-m`` (m = 0..12) it is a
    multiple of, up to the float's own rounding (stamps may be written with a number of
    significant digits, not of decimals: MATLAB's ``num2str`` writes 0.0003328 and 11.6474)."""
    q = np.full(t.size, 1e-12)
    open_ = np.ones(t.size, dtype=bool)
    for m in range(0, 13):
        step = 10.0 ** -m
        r = t / step
        hit = open_ & (np.abs(r - np.round(r)) <= 1e-6 + 1e-12 * np.abs(r))
        q[hit] = step
        open_ &= ~hit
    return q


def _stamp_line(slot: np.ndarray, t: np.ndarray) -> tuple[float, float, np.ndarray, np.ndarray, float]:
    """The least-squares line ``t0 + dt * slot`` through the stamps ``t`` (the uniform grid the
    time-grid checks test), each stamp's distance from it, each stamp's last written digit
    (:func:`_last_digit`) and their median ``q``: ``(dt, t0, off, digit, q)``."""
    dt, t0 = np.polyfit(slot, t, 1)
    digit = _last_digit(t)
    return float(dt), float(t0), np.abs(t - (t0 + dt * slot)), digit, float(np.median(digit))


def rounded_time_grid(t: np.ndarray, x: np.ndarray | None = None) -> tuple[np.ndarray, float, float] | None:
    """The uniform grid behind rounded time stamps, or ``None``.

    The stamps are taken as a uniform grid rounded to their last written digit when their steps
    spread by more than :data:`ROUNDED_STEP_SPREAD` of the median step and every stamp lies
    within half its own last digit (:func:`_last_digit`; at most the median stamp's, ``q``) of the
    least-squares line ``t0 + k dt``, with a margin of ``q / 20`` for the line's own error. Irregular
    sampling fails that test and is left alone; so does a grid with a gap or a lost sample (a
    lost sample's slot is :func:`lost_slots`'s to put back, with the grid).

    A stamp resolution as coarse as the step itself leaves one ambiguity: a grid whose step is
    a little longer than ``q`` gives a rare step of ``2q``, and so does a lost sample on a grid of
    step ``q``. A signal ``x`` sampled at the stamps tells them apart: across a lost sample it moves
    twice as far as across its neighbouring steps (a probe's file with one row deleted had been
    re-timed by up to half a step).

    Parameters
    ----------
    t : ndarray (n,)
        Strictly increasing, finite time stamps [s].
    x : ndarray (n,), optional
        A smooth channel at the stamps (the displacement), to tell lost samples from rounding.

    Returns
    -------
    (grid, q, largest) or None
        The restored stamps ``t0 + k dt`` [s], the stamps' (median) resolution ``q`` [s] and
        the largest change of a stamp [s].
    """
    n = t.size
    if n < 3:
        return None
    d = np.diff(t)
    median = float(np.median(d))
    if not (median > 0.0) or (float(d.max()) - float(d.min())) <= ROUNDED_STEP_SPREAD * median:
        return None
    k = np.arange(n, dtype=float)
    # a stamp that happens to end in zeros (12.0 written as 12) is as coarse as the others
    dt, t0, off, digit, q = _stamp_line(k, t)
    grid = t0 + dt * k
    if not q > 0.01 * dt or np.any(off > 0.5 * np.minimum(digit, q) + 0.05 * q):
        return None
    if x is not None and _lost_samples(d, np.asarray(x, dtype=float), median):
        return None
    return grid, q, float(off.max())


def _lost_samples(d: np.ndarray, x: np.ndarray, median: float) -> bool:
    """Whether the long steps of ``d`` (at least 1.5 median steps) are lost samples: a smooth
    signal ``x`` moves across them 1.5 times or more as far as across the steps beside them
    (rounded stamps of a uniform grid: about as far)."""
    dx = np.abs(np.diff(x))
    long = np.flatnonzero(d >= 1.5 * median)
    long = long[(long > 0) & (long < d.size - 1)]
    if long.size == 0 or long.size > 0.05 * d.size:
        return False
    # a long step next to a missing value (NaN, filled later) cannot be judged; the others can
    long = long[np.isfinite(dx[long - 1]) & np.isfinite(dx[long]) & np.isfinite(dx[long + 1])]
    if long.size == 0:
        return False
    beside = 0.5 * (dx[long - 1] + dx[long + 1])
    moving = beside > 1e-6 * (float(np.ptp(x[np.isfinite(x)])) if np.isfinite(x).any() else 0.0)
    if not moving.any():
        return False
    return float(np.median(dx[long][moving] / beside[moving])) >= 1.5


def coarse_time_grid(t: np.ndarray, channels: dict | None = None) -> tuple[np.ndarray, float, int] | None:
    """The uniform grid behind time stamps coarser than the sampling step, or ``None``.

    A logger whose clock ticks more slowly than it samples (a 1-ms clock at 3 kHz) writes each
    stamp two or three times. Read as glitches, the repeated stamps had their rows dropped: two
    thirds of such a test lost, and the rows kept stamped up to a tick early. Accepted when the
    stamps never go back, the stamps' resolution ``q`` (their last written digit,
    :func:`_last_digit`) is coarser than the mean step ``dt``, every stamp lies within ``q/2``
    (and a twentieth of ``q``) of one line ``t0 + k dt`` of the row numbers (rounded or truncated
    stamps: a truncating clock's half tick goes into ``t0``; the grid returned starts at the first
    stamp), the stamps repeat in about the share ``1 - dt/q`` of the steps such a clock gives
    (half to one and a half times it, at least :data:`COARSE_MIN_REPEATS`), at most
    :data:`COARSE_MISSING_SHARE` of the stamps are missing (their rows get their slots' times),
    and the rows that repeat a stamp are not mostly copies of the row before in every channel (a
    logger's double writes are :func:`repair_samples`' ``duplicate``; a held reading or a test at
    rest copies a few). A clock that also lost a row is not restored: its line is a step off from
    there on, and its repeated stamps are dropped as glitches.

    Parameters
    ----------
    t : ndarray (n,)
        Time stamps as read [s].
    channels : dict of str to ndarray or None, optional
        The other columns as read (a row equal to the one before in every channel is a copy).

    Returns
    -------
    (grid, q, repeats) or None
        The restored stamps [s], the stamps' resolution [s] and how many rows repeat a stamp.
    """
    n = t.size
    finite = np.isfinite(t)
    if n < 16 or not finite[0] or finite.sum() < (1.0 - COARSE_MISSING_SHARE) * n:
        return None
    tf = t[finite]
    d = np.diff(tf)
    repeats = int(np.count_nonzero(d == 0.0))
    if np.any(d < 0.0) or repeats < COARSE_MIN_REPEATS:
        return None
    k = np.arange(n, dtype=float)
    dt, _, off, _, q = _stamp_line(k[finite], tf)
    if not (dt > 0.0 and q > dt) or np.any(off > 0.55 * q):
        return None
    # a clock of tick q at step dt repeats a stamp in a share 1 - dt/q of the steps
    expected = (1.0 - dt / q) * d.size
    if not 0.5 * expected <= repeats <= 1.5 * expected + COARSE_MIN_REPEATS:
        return None
    present = [np.asarray(v, dtype=float) for v in (channels or {}).values() if v is not None]
    if present:
        same = t[1:] == t[:-1]  # the stamp repeats ...
        for v in present:       # ... and so does every channel: a copy of the row before
            same &= (v[1:] == v[:-1]) | (np.isnan(v[1:]) & np.isnan(v[:-1]))
        if np.count_nonzero(same) > 0.5 * repeats:
            return None
    # anchored at the first stamp (a truncating clock's line starts half a tick before it; a
    # constant shift of every channel changes nothing the model sees)
    return t[0] + dt * k, q, repeats


def lost_slots(t: np.ndarray, x: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """The uniform grid behind stamps from which single samples were lost, or ``None``.

    A logger that misses a sample period and writes nothing for it leaves one step twice as long
    as the others (on the Dyke files' 0.1-ms stamps of a 0.333-ms step: 0.7 ms among 0.3 and 0.4
    ms). Left as read, such a step spreads the steps beyond any uniform grid: the rounding of
    :func:`rounded_time_grid` is not restored, and every derivative taken on the median step
    (0.3 ms there, against 0.333) is 11 % off. Accepted when each step is one or two median steps
    (rounded to the nearest), at most :data:`LOST_MAX_SHARE` of them two, and every stamp lies on
    one line ``t0 + k dt`` of the slot numbers ``k`` within half its last digit (with a margin of
    a twentieth of the stamps' resolution and 1e-6 of a step). Where the stamps are as coarse as
    half a step, a rare step of two is also what rounding gives, and a smooth channel ``x`` must
    move across the long steps twice as far as beside them (:func:`_lost_samples`). Longer holes
    are gaps (:data:`GAP_FACTOR`), irregular stamps stay as read; a file with such a gap anywhere,
    or too short for one double step to be within :data:`LOST_MAX_SHARE` of its steps (about
    100 samples), keeps its stamps as read.

    Parameters
    ----------
    t : ndarray (n,)
        Strictly increasing, finite time stamps [s].
    x : ndarray (n,), optional
        A smooth channel at the stamps (the displacement).

    Returns
    -------
    (slot, grid) or None
        The slot number of each stamp (int, ``slot[0] = 0``) and the grid's stamps
        ``t0 + dt * arange(slot[-1] + 1)`` [s].
    """
    n = t.size
    if n < 8:
        return None
    d = np.diff(t)
    median = float(np.median(d))
    if not median > 0.0:
        return None
    r = np.rint(d / median)
    long = r == 2.0
    if not long.any() or np.any((r < 1.0) | (r > 2.0)) or long.sum() > LOST_MAX_SHARE * d.size:
        return None
    slot = np.r_[0, np.cumsum(r.astype(np.int64))]
    dt, t0, off, digit, q = _stamp_line(slot.astype(float), t)
    if not dt > 0.0 or np.any(off > 0.5 * np.minimum(digit, q) + 0.05 * q + 1e-6 * dt):
        return None
    if q >= 0.5 * dt and (x is None or not _lost_samples(d, np.asarray(x, dtype=float), median)):
        return None
    return slot, t0 + dt * np.arange(int(slot[-1]) + 1, dtype=float)


def _decimal_resolution(value: float) -> float:
    """The last decimal place ``value`` is written to (``-7.275`` -> 0.001; a computed value
    such as ``-7.2750000000027`` counts as ``-7.275``), at most 1e-12 of its size."""
    v = abs(float(value))
    if v == 0.0 or not math.isfinite(v):
        return 0.0
    for k in range(-int(math.floor(math.log10(v))) - 1, 16):
        q = 10.0 ** -k
        if abs(v / q - round(v / q)) <= 1e-6:
            return q
    return 0.0


def held_samples(displacement: np.ndarray, force: np.ndarray) -> np.ndarray:
    """The samples of readings written into more than one time slot (``held`` in the module docstring).

    Parameters
    ----------
    displacement, force : ndarray (n,)
        The two measured channels as read (NaN where missing: never part of a held run).

    Returns
    -------
    ndarray of bool (n,)
        True at every slot of a held run (the reading and its repeats). Empty (all False) when
        held runs would cover more than :data:`HELD_MAX_SHARE` of the samples: readings repeated
        throughout are the file's make-up (a file resampled by repeating readings), not missed
        samples (:func:`repair_samples` reports them once and leaves them as read).
    """
    x = np.asarray(displacement, dtype=float)
    f = np.asarray(force, dtype=float)
    mask = np.zeros(x.size, dtype=bool)
    runs = held_runs(x, f)
    if not _held_throughout(runs, x.size):
        for a, b in runs:
            mask[a:b + 1] = True
    return mask


def _held_throughout(runs: list[tuple[int, int]], n: int) -> bool:
    """Held runs over more than :data:`HELD_MAX_SHARE` of ``n`` samples: the file's make-up."""
    return sum(b - a + 1 for a, b in runs) > HELD_MAX_SHARE * n


def held_runs(displacement: np.ndarray, force: np.ndarray) -> list[tuple[int, int]]:
    """``(first, last)`` slot of each held run (:func:`held_samples`), every run kept.

    Parameters
    ----------
    displacement, force : ndarray (n,)
        The two measured channels as read.
    """
    x = np.asarray(displacement, dtype=float)
    f = np.asarray(force, dtype=float)
    n = x.size
    if n < 4 or not (np.isfinite(x).sum() > 3 and np.isfinite(f).sum() > 3):
        return []
    scale_f = float(np.nanmax(np.abs(f - np.nanmedian(f))))
    if scale_f <= 0.0:
        return []  # a force that never changes repeats everywhere: no evidence of a held reading
    tol_x = HELD_TOLERANCE * float(np.nanmax(np.abs(x - np.nanmedian(x))))
    tol_f = HELD_TOLERANCE * scale_f
    dx, df = np.diff(x), np.diff(f)
    same = (np.abs(dx) <= tol_x) & (np.abs(df) <= tol_f)
    if not same.any():
        return []  # most files: no repeat at all, nothing more to sort
    # the channel's own step: the smallest gap between two of its distinct values (an encoder's
    # count, a converter's step), whatever digits the file shows
    gaps = np.diff(np.unique(x[np.isfinite(x)]))
    gaps = gaps[gaps > tol_x]
    converter = float(gaps.min()) if gaps.size else 0.0
    out = []
    for a, b in _runs(same):  # x[a..b] (b - a + 1 slots) hold one reading
        if a < 1 or b + 1 >= n or b - a + 1 > HELD_MAX_SLOTS:
            continue  # at the file's ends, or a pause: not a missed sample period
        before, after = x[a] - x[a - 1], x[b + 1] - x[b]
        # the displacement's resolution there: its converter's step, or the decimal places its
        # neighbours are written to where coarser (a file of a few significant digits is coarser
        # at the stroke's ends than near 0)
        quantum = max(converter, _decimal_resolution(x[a - 1]), _decimal_resolution(x[a]),
                      _decimal_resolution(x[b + 1]))
        if before * after > 0 and min(abs(before), abs(after)) >= HELD_STEPS * quantum:
            out.append((a, b))
    return out


def one_sided_difference(t: np.ndarray, x: np.ndarray, v: np.ndarray,
                         usable: np.ndarray | None = None) -> str | None:
    """``"backward"`` or ``"forward"`` when the velocity column ``v`` is that difference of the
    displacement ``x`` (``difference`` in the module docstring), else None.

    Parameters
    ----------
    t, x, v : ndarray (n,)
        Time [s], displacement [m] and the file's velocity [m/s], finite.
    usable : ndarray of bool (n,), optional
        Samples to judge by (a filled or interpolated sample is not the file's).
    """
    t, x, v = (np.asarray(a, dtype=float) for a in (t, x, v))
    n = t.size
    if n < 8:
        return None
    ok = np.ones(n, dtype=bool) if usable is None else np.asarray(usable, dtype=bool)
    peak = float(np.max(np.abs(v[ok]))) if ok.any() else 0.0
    if peak <= 0.0:
        return None
    slope = np.diff(x) / np.diff(t)
    pair = ok[1:] & ok[:-1]
    if pair.sum() < max(8, n // 2):
        return None
    for name, at in (("backward", v[1:]), ("forward", v[:-1])):
        # a dropped row or a glitch leaves a pair or two off: the rest decides
        off = np.abs(at[pair] - slope[pair]) > DIFFERENCE_TOLERANCE * peak
        if off.sum() <= DIFFERENCE_EXCEPTIONS * pair.sum():
            return name
    return None


def _copies_of_kept_rows(t: np.ndarray, keep: np.ndarray, channels: dict) -> np.ndarray:
    """Whether each dropped sample is an exact copy of a kept one: the same time stamp and the
    same value in every channel (NaN equal to NaN). A row written twice, or a block a logger
    wrote again after a restart, loses nothing when dropped."""
    kept = np.flatnonzero(keep)
    out = np.zeros(t.size, dtype=bool)
    cand = np.flatnonzero(~keep & np.isfinite(t))
    if cand.size == 0 or kept.size == 0:
        return out
    j = np.minimum(np.searchsorted(t[kept], t[cand]), kept.size - 1)
    ref = kept[j]
    same = t[ref] == t[cand]
    for values in channels.values():
        if values is None:
            continue
        v = np.asarray(values, dtype=float)
        same &= (v[cand] == v[ref]) | (np.isnan(v[cand]) & np.isnan(v[ref]))
    out[cand[same]] = True
    return out


def _rounded_finding(stamps: np.ndarray, grid: np.ndarray, q: float) -> Finding:
    """The ``rounded`` finding of stamps restored to ``grid`` (the same samples), written to ``q``."""
    d = np.diff(stamps)
    step = float((grid[-1] - grid[0]) / (grid.size - 1))
    off = np.abs(stamps - grid)
    largest = float(off.max())
    return Finding("rounded", "time", float(grid[0]), float(grid[-1]), int(np.count_nonzero(off > 0.01 * step)),
                   f"time stamps rounded to {q:g} s: steps {d.min() * 1e3:.4g}-{d.max() * 1e3:.4g} ms "
                   f"on a uniform {step * 1e3:.4g} ms grid ({1.0 / step:.5g} Hz; stamps off it by up to "
                   f"{largest * 1e3:.3g} ms, {100.0 * largest / step:.0f} % of a step): the grid restored",
                   excluded=False)


def repair_samples(time: np.ndarray, channels: dict, label: str = "test",
                   lines: Sequence[int] | None = None, min_usable: int = 10,
                   keep_flagged: bool = False) -> tuple[np.ndarray, dict, np.ndarray, list]:
    """Drop bad time stamps and fill missing values, so that a test can be built from raw columns.

    Parameters
    ----------
    time : ndarray (n,)
        Time stamps as read [s] (may repeat, go backwards or be NaN).
    channels : dict of str to ndarray (n,) or None
        The other columns as read (SI), NaN where a value is missing (``None``: absent).
    label : str
        File name, for the messages.
    lines : sequence of int, optional
        The file line of each sample (for the messages).
    min_usable : int
        Fewer usable samples than this, or than a tenth of the samples, is an error.
    keep_flagged : bool
        Report held readings (:func:`held_samples`) but keep their values as read and their
        samples in (``--keep-flagged``); missing values are filled and excluded either way.

    Returns
    -------
    time : ndarray
        Strictly increasing.
    channels : dict
        Finite: missing values interpolated linearly in time (the end values held), so that an
        input channel can still drive the model; those samples are excluded.
    excluded : ndarray of bool
        Samples to leave out of fits and errors.
    findings : list of Finding

    Raises
    ------
    InputError
        Too little is left; the message names the first bad sample (its file line when given)
        and the column.
    """
    t = np.asarray(time, dtype=float)
    n = t.size
    need = max(min_usable, int(math.ceil(0.1 * n)))
    findings: list[Finding] = []
    coarse = coarse_time_grid(t, channels)
    if coarse is not None:
        # a clock coarser than the sampling (a 1-ms clock at 3 kHz): every row is a sample, the
        # repeated stamps are the clock's, not the logger's glitches
        grid, q, repeats = coarse
        step = float((grid[-1] - grid[0]) / (grid.size - 1))
        findings.append(Finding("rounded", "time", float(grid[0]), float(grid[-1]), repeats,
                                f"time stamps written to {q:g} s, coarser than the {1e3 * step:.4g} ms step "
                                f"({repeats} rows repeat the stamp before them): the uniform grid restored "
                                f"({1.0 / step:.5g} Hz), every row kept", excluded=False))
        t = grid
    finite_t = np.isfinite(t)
    tt = np.where(finite_t, t, -np.inf)
    prev = np.maximum.accumulate(np.r_[-np.inf, tt[:-1]])
    keep = finite_t & (tt > prev)
    if not keep.all():
        i = int(np.flatnonzero(~keep)[0])
        if keep.sum() < need:
            what = (f"got {t[i]:g} s after {prev[i]:g} s" if finite_t[i] else f"got {t[i]}")
            raise InputError(f"{_where(lines, i, label)}: column 'time': expected strictly increasing "
                             f"finite values, {what} ({int(keep.sum())} usable samples left, "
                             f"at least {need} needed)")
        kept_t = np.where(keep, t, np.nan)
        exact = _copies_of_kept_rows(t, keep, channels)
        if exact.any():
            # a logger that wrote rows twice: nothing is lost by dropping the copies, and the
            # samples around them are intact (no exclusion, no settling after them)
            rows = np.flatnonzero(exact)
            findings.append(Finding("duplicate", "time", float(t[rows[0]]), float(t[rows[-1]]), int(rows.size),
                                    f"{rows.size} row(s) copy an earlier row exactly (time and every channel; "
                                    f"first at {_where(lines, int(rows[0]), label)}): the copies dropped, "
                                    "nothing lost", excluded=False))
        restarts = set(clock_restarts(t, channels))  # the rule read_tests splits a file by
        for kind, sel, text in (("time", ~finite_t, "time stamp missing: sample dropped"),
                                ("time", finite_t & (tt == prev) & ~exact, "repeated time stamp: sample dropped"),
                                ("time", finite_t & (tt < prev) & ~exact, "time goes backwards: sample dropped")):
            for a, b in _runs(sel):
                before = kept_t[:a][np.isfinite(kept_t[:a])]
                t0 = float(before[-1]) if before.size else float(np.nanmin(kept_t))
                if text.startswith("time goes backwards") and a in restarts:
                    # a second recording appended to the first: say so, not a glitch per row
                    text_here = (f"the clock restarts at {t[a]:g} s after {t0:g} s: the {b - a} rows from "
                                 "there on (a second recording appended?) dropped; the commands read it as a test of its own")
                else:
                    text_here = text
                findings.append(Finding(kind, "time", t0, t0, b - a,
                                        f"{text_here} ({_where(lines, a, label)})"))
    t = t[keep]
    lines = None if lines is None else [ln for ln, k in zip(lines, keep) if k]
    channels = {name: None if values is None else np.asarray(values, dtype=float)[keep]
                for name, values in channels.items()}
    # single samples lost from a uniform grid: their slots put back, missing in every channel
    lost = np.zeros(t.size, dtype=bool)
    restored = lost_slots(t, channels.get("displacement"))
    if restored is not None:
        slot, grid = restored
        lost = np.ones(grid.size, dtype=bool)
        lost[slot] = False
        for name, values in channels.items():
            if values is not None:
                channels[name] = np.full(grid.size, np.nan)
                channels[name][slot] = values
        if lines is not None:  # a lost slot is named by the file line after it
            after = np.searchsorted(slot, np.arange(grid.size))
            lines = [lines[int(i)] for i in after]
        stamps, t = t, grid
        for a, b in _runs(lost):
            findings.append(Finding("lost", "time", float(t[a]), float(t[b - 1]), b - a,
                                    f"no row for {b - a} slot(s) of the uniform {1e3 * (t[1] - t[0]):.4g} ms grid "
                                    "(a logger's lost sample): put back, interpolated to drive the model, "
                                    f"not fitted ({_where(lines, a, label)})"))
        if np.any(np.abs(stamps - grid[slot]) > 0.01 * (t[1] - t[0])):
            findings.append(_rounded_finding(stamps, grid[slot], float(np.median(_last_digit(stamps)))))
    else:
        rounded = rounded_time_grid(t, channels.get("displacement"))
        if rounded is not None:
            grid, q, _ = rounded
            findings.append(_rounded_finding(t, grid, q))
            t = grid
    excluded = np.zeros(t.size, dtype=bool)
    out: dict = {}
    first_bad = None
    # readings written into more than one time slot: missing values in every measured channel
    held = np.zeros(t.size, dtype=bool)
    if channels.get("displacement") is not None and channels.get("force") is not None:
        runs_held = held_runs(channels["displacement"], channels["force"])
        if _held_throughout(runs_held, t.size):
            slots = sum(b - a + 1 for a, b in runs_held)
            # repeated throughout: the file's make-up, not missed samples; said once, left as read
            findings.append(Finding("held", "displacement", float(t[0]), float(t[-1]), slots,
                                    f"readings of the displacement and the force repeat in {slots} of "
                                    f"{t.size} samples throughout the file (a file resampled by repeating "
                                    "readings?): left as read; resample it at the rate it was measured at",
                                    excluded=False))
            runs_held = []
        for a, b in runs_held:
            findings.append(Finding("held", "displacement", float(t[a]), float(t[b]), b - a + 1,
                                    f"one reading of the displacement and the force in {b - a + 1} time slots "
                                    "while the stroke moves (a logger's missed sample)"
                                    + ("" if keep_flagged else ": interpolated to drive the model, not fitted")
                                    + f" ({_where(lines, a, label)})", excluded=not keep_flagged))
            if not keep_flagged:
                held[a:b + 1] = True
    for name, values in channels.items():
        if values is None:
            out[name] = None
            continue
        v = values
        if name == "velocity" and np.mean(np.isnan(v) & ~held & ~lost) > DEAD_VELOCITY_SHARE:
            # a dead optional channel: the displacement's derivative drives the model instead,
            # as for a file without the column (excluding its samples would empty the test)
            n_missing = int(np.count_nonzero(np.isnan(v) & ~lost))
            findings.append(Finding("velocity", "velocity", float(t[0]), float(t[-1]), 0,
                                    f"the velocity column is missing in {n_missing} of {v.size} samples: the "
                                    "column is dropped and the central difference of the displacement "
                                    "drives the model", excluded=False))
            out[name] = None
            continue
        if np.any(np.isinf(v)):
            i = int(np.flatnonzero(np.isinf(v))[0])
            raise InputError(f"{_where(lines, i, label)}: column {name!r}: expected a finite number, "
                             f"got {v[i]}")
        if name in _MEASURED and held.any():
            v = np.where(held, np.nan, v)
        # after the held slots (missing: never a spike; a logger's velocity jumps at them)
        spiked = spike_samples(v) if name in _MEASURED else np.zeros(v.size, dtype=bool)
        if spiked.any():
            runs_spiked = _runs(spiked)
            many = int(spiked.sum()) > SPIKE_MAX_SHARE * v.size
            if many:
                findings.append(Finding("spike", name, float(t[runs_spiked[0][0]]), float(t[runs_spiked[-1][1] - 1]),
                                        int(spiked.sum()),
                                        f"{int(spiked.sum())} samples in {len(runs_spiked)} runs jump off their "
                                        f"neighbours and back, more than {100 * SPIKE_MAX_SHARE:g} % of the samples: "
                                        "something the channel does, not glitches; left as read", excluded=False))
            for a, b in ([] if many else runs_spiked):
                med = float(np.median(v[max(a - SPIKE_REACH, 0):b + SPIKE_REACH]))
                findings.append(Finding("spike", name, float(t[a]), float(t[b - 1]), b - a,
                                        f"{b - a} sample(s) jump to {float(v[a]):.4g} off their neighbours' "
                                        f"{med:.4g} and back (a glitch)"
                                        + ("" if keep_flagged else ": interpolated, not fitted")
                                        + f" ({_where(lines, a, label)})", excluded=not keep_flagged))
            if many or keep_flagged:
                spiked[:] = False
            v = np.where(spiked, np.nan, v)
        bad = np.isnan(v)
        if bad.any():
            # the file's own missing values (held slots, spikes, lost slots: their findings)
            missing = bad & ~held & ~spiked & ~lost
            if missing.any() and (first_bad is None or int(np.argmax(missing)) < first_bad[0]):
                first_bad = (int(np.argmax(missing)), name)
            ok = ~bad
            for a, b in _runs(bad & ~held & ~spiked & ~lost):
                findings.append(Finding("nan", name, float(t[a]), float(t[b - 1]), b - a,
                                        "missing values (NaN): "
                                        + ("interpolated to drive the model" if name in _INPUTS
                                           else "filled, not fitted")
                                        + f" ({_where(lines, a, label)})"))
            if ok.sum() >= 2:
                v = np.interp(t, t[ok], v[ok])
            excluded |= bad
        out[name] = v
    if first_bad is not None and int((~excluded).sum()) < need:
        i, name = first_bad
        raise InputError(f"{_where(lines, i, label)}: column {name!r}: expected a finite number, got "
                         f"nan ({int((~excluded).sum())} usable samples left, at least {need} needed)")
    # a velocity column that is the displacement's one-sided difference: half a step off its time
    v_col, x_col = out.get("velocity"), out.get("displacement")
    if v_col is not None and x_col is not None:
        kind = one_sided_difference(t, x_col, v_col, ~excluded)
        if kind is not None:
            out["velocity"] = np.gradient(x_col, t, edge_order=2 if t.size > 2 else 1)
            step = float(np.median(np.diff(t)))
            findings.append(Finding("difference", "velocity", float(t[0]), float(t[-1]), 0,
                                    f"the velocity column is the displacement's {kind} difference, half a "
                                    f"step ({0.5e3 * step:.3g} ms) {'late' if kind == 'backward' else 'early'}: "
                                    "replaced by the central difference", excluded=False))
        else:
            scale = velocity_scale(t, x_col, v_col, ~excluded)
            if scale is not None and not (1.0 - VELOCITY_GAIN_TOLERANCE <= scale
                                          <= 1.0 + VELOCITY_GAIN_TOLERANCE):
                # a unit, gain or sign error of the channel: the model would be driven by a motion
                # the damper never had, and the screening would flag every reversal
                out["velocity"] = np.gradient(x_col, t, edge_order=2 if t.size > 2 else 1)
                what = "its sign inverted" if scale < 0 else "a unit or gain error"
                findings.append(Finding("velocity", "velocity", float(t[0]), float(t[-1]), 0,
                                        f"the velocity column is {scale:.4g} times the derivative of the "
                                        f"displacement ({what}): replaced by the central difference",
                                        excluded=False))
    # a measured coil input that only wanders around its level (a current sensor's noise, a
    # converter's 1-mA steps): the level, not a command that changes within the test
    for name, unit in (("current", "A"), ("voltage", "V")):
        u = out.get(name)
        if u is None:
            continue
        level = steady_level(u[~excluded] if (~excluded).any() else u)
        if level is not None and np.ptp(u) > 0:
            spread = float(np.max(np.abs(u[~excluded] - level))) if (~excluded).any() else float(np.ptp(u))
            out[name] = np.full(u.shape, level)
            findings.append(Finding("steady", name, float(t[0]), float(t[-1]), 0,
                                    f"the {name} stays within {spread:.3g} {unit} of {level:.6g} {unit} "
                                    f"(a measured level's noise or a converter's steps, under "
                                    f"{100 * STEADY_SHARE:g} % of it or {STEADY_FLOOR:g} {unit}): read as the "
                                    f"constant {level:.6g} {unit}", excluded=False))
    return t, out, excluded, findings


#: The force-velocity cross-correlation above which the force column is a velocity's (no damper
#: force has so little hysteresis: 72 measured files, UTFSM, Dyke and LabControl, peak at 0.84-0.98).
VELOCITY_LIKE_CORRELATION = 0.999


#: A coil input within this share of its median (or :data:`STEADY_FLOOR`, the larger) over a
#: whole test is one level measured with noise (the tolerance ``--validate`` grants a recording's
#: level, :func:`damper.diagnosis.loop.check_recordings`) ...
STEADY_SHARE = 0.05
#: ... or within this many amperes (volts) of it: a sensor's offset around 0 A.
STEADY_FLOOR = 0.02


def steady_level(u: np.ndarray) -> float | None:
    """The level a measured coil input holds within noise (its median), or None when it changes.

    A probe (2026-11-28) gave the residual loop a current of 1 A measured with 0.5 % noise, and
    one read by a converter in 1-mA steps: the Spencer base fitted its voltage laws on nodes
    0.999 and 1.001 A (c1 from 86 to 16 kN s/m across 2 mA) and scored 0.105 where the same test
    at a constant 1 A scores 0.078; ``sbib identify --data`` refused it ("current varies over
    the test"). Every sample within :data:`STEADY_SHARE` of the median, or :data:`STEADY_FLOOR`,
    reads as that median.

    Parameters
    ----------
    u : ndarray
        The input's usable samples (A or V).
    """
    u = np.asarray(u, dtype=float)
    if u.size == 0 or not np.all(np.isfinite(u)):
        return None
    level = float(np.median(u))
    if float(np.max(np.abs(u - level))) <= max(STEADY_SHARE * abs(level), STEADY_FLOOR):
        return level
    return None


def velocity_scale(t: np.ndarray, x: np.ndarray, v: np.ndarray, usable: np.ndarray | None = None) -> float | None:
    """The velocity column's scale against the displacement's derivative: its RMS over the
    derivative's, signed by their correlation (a lag between them changes neither); ``None``
    where it cannot be judged (a short, flat or non-uniformly sampled test, or a correlation
    below 0.8 in magnitude: the channels disagree by more than a scale, the screening's matter).

    Parameters
    ----------
    t, x, v : ndarray (n,)
        Time [s], displacement [m] and the file's velocity [m/s], finite.
    usable : ndarray of bool (n,), optional
        Samples to judge by.
    """
    t, x, v = (np.asarray(a, dtype=float) for a in (t, x, v))
    if t.size < 32:
        return None
    steps = np.diff(t)
    dt = float(np.median(steps))
    if not dt > 0.0 or np.ptp(steps) > 0.5 * dt or np.ptp(x) <= 0.0:
        return None
    ok = np.ones(t.size, dtype=bool) if usable is None else np.asarray(usable, dtype=bool)
    if ok.sum() < 32:
        return None
    # the derivative smoothed over the motion's band (differentiation amplifies the displacement's
    # noise); the velocity's own noise adds to its RMS in quadrature, far below the tolerance
    deriv = _derivative(t, x, 1.0 / dominant_frequency(t, x), band_edge(t, v))
    d, w = deriv[ok] - np.mean(deriv[ok]), v[ok] - np.mean(v[ok])
    rms_d, rms_w = float(np.sqrt(np.mean(d * d))), float(np.sqrt(np.mean(w * w)))
    if not (rms_d > 0.0 and rms_w > 0.0):
        return None
    corr = float(np.mean(d * w) / (rms_d * rms_w))
    if abs(corr) < 0.8:
        return None
    return math.copysign(rms_w / rms_d, corr)


# ---------------------------------------------------------------------------------------------
# the checks
# ---------------------------------------------------------------------------------------------
def net_work(t, force, rate, usable=None) -> tuple[float, float]:
    """The work [J] a force does on a motion, ∫ F·ẋ dt over the usable samples, and its share
    of the absolute work ∫ |F·ẋ| dt (NaN when that is zero): the ``polarity`` rule's measure,
    also applied to force-driven tests by :func:`damper.hysteresis.files.data_flaws`.

    Parameters
    ----------
    t : array_like (n,)
        Sample times [s].
    force : array_like (n,)
        Force [N].
    rate : array_like (n,)
        Velocity of the motion the force acts on [m/s].
    usable : array_like (n,) of bool, optional
        Samples to count (default all).
    """
    power = np.asarray(force, dtype=float) * np.asarray(rate, dtype=float) * np.gradient(np.asarray(t, dtype=float))
    if usable is not None:
        power = power[np.asarray(usable, dtype=bool)]
    work, absolute = float(np.sum(power)), float(np.sum(np.abs(power)))
    return work, (work / absolute if absolute > 0.0 else math.nan)


def _channel(test, name: str):
    value = getattr(test, name, None)
    return None if value is None else np.asarray(value, dtype=float)


def _input_name(test) -> str | None:
    for name in ("voltage", "current"):
        if getattr(test, name, None) is not None:
            return name
    return None


def screen(test: Any, prior: Sequence[Finding] = (), prior_excluded: np.ndarray | None = None,
           velocity_measured: bool | None = None) -> Screening:
    """Screen one damper test (see the module docstring for the checks).

    Parameters
    ----------
    test : DamperTest
        The test (finite samples, strictly increasing time).
    prior : sequence of Finding
        Findings of :func:`repair_samples` (NaN, time stamps) to carry into the report.
    prior_excluded : ndarray of bool, optional
        Samples those findings exclude.
    velocity_measured : bool, optional
        Whether the velocity is a channel of its own (default: the test's
        ``metadata["velocity_from_file"]``, else True); a velocity computed from the
        displacement is not compared with it.

    Returns
    -------
    Screening
    """
    t = np.asarray(test.time, dtype=float)
    x = np.asarray(test.displacement, dtype=float)
    v = np.asarray(test.velocity, dtype=float)
    f = np.asarray(test.force, dtype=float)
    n = t.size
    name = str(getattr(test, "name", "") or getattr(test, "source", "") or "test")
    if velocity_measured is None:
        velocity_measured = bool(getattr(test, "metadata", {}).get("velocity_from_file", True))
    findings: list[Finding] = list(prior)
    excluded = np.zeros(n, dtype=bool) if prior_excluded is None else np.asarray(prior_excluded, bool).copy()
    input_bad = np.zeros(n, dtype=bool)
    held = np.zeros(n, dtype=bool)  # a logger's held readings and spikes: interpolated, no fault of the rig
    for fd in prior:
        if fd.kind in _INTERPOLATED and fd.excluded:
            held |= (t >= fd.t_start) & (t <= fd.t_end)
        # a finding reported only (a rounded time grid, restored) is no fault of the input
        # a held reading or a spike is interpolated over a slot or a few in mid-stroke: the
        # model's state after it is off by that interpolation only, so no settling follows it
        if (fd.channel in _INPUTS or fd.channel == "time") and fd.excluded and fd.kind not in _INTERPOLATED:
            sel = (t >= fd.t_start) & (t <= fd.t_end)
            input_bad |= sel & excluded if fd.kind == "nan" else sel
    estimates: dict = {}
    if n < 8:
        return Screening(tuple(findings), ~excluded, estimates, name)
    steps = np.diff(t)
    dt = float(np.median(steps))
    period = 1.0 / dominant_frequency(t, x)
    lo_x, hi_x = np.percentile(x, [0.5, 99.5])
    stroke = float(hi_x - lo_x)

    # gaps: the motion inside is unknown; the sample after the gap starts a new history
    for i in np.flatnonzero(steps > GAP_FACTOR * dt):
        findings.append(Finding("gap", "time", float(t[i]), float(t[i + 1]), 1,
                                f"no sample for {steps[i]:.4g} s ({steps[i] / dt:.1f} median steps)"))
        excluded[i + 1] = True
        input_bad[i + 1] = True

    # idle: no motion over a dominant period while the force rests too (a rig waiting between
    # runs); a quiet stretch of a random motion whose force still changes is data, not idle
    idle = np.zeros(n, dtype=bool)
    lo_f, hi_f = np.percentile(f, [0.5, 99.5])
    f_range = float(hi_f - lo_f)
    if stroke > 0:
        w = max(int(round(period / dt)), 5)
        if w < n:
            xw = sliding_window_view(x, w)
            fw = sliding_window_view(f, w)
            quiet = (((xw.max(axis=1) - xw.min(axis=1)) < IDLE_FRACTION * stroke)
                     & ((fw.max(axis=1) - fw.min(axis=1)) < 0.1 * f_range))
            for a, b in _runs(quiet):
                idle[a:b + w - 1] = True
            # the rig stopping at a reversal: the stroke is still from there on, and the force
            # relaxes to rest (a decay, not a cycle) before the window above calls it idle; that
            # stretch is the idle span's, not a frozen sensor's (a probe's 1-s rest was reported
            # as both)
            for kind, a, b, _ in stuck_spans(x):
                if kind != "stuck" or not idle[a:b].any() or idle[a:b].all():
                    continue
                runs = [(a + c, a + e) for c, e in _runs(~idle[a:b])]
                if all(abs(f[e - 1] - f[c]) >= 0.8 * np.ptp(f[c:e]) for c, e in runs):
                    idle[a:b] = True
            for a, b in _runs(idle):
                findings.append(Finding("idle", "displacement", float(t[a]), float(t[b - 1]), b - a,
                                        f"no motion (less than {100 * IDLE_FRACTION:g} % of the "
                                        f"{stroke:.4g} m stroke, the force at rest) for "
                                        f"{t[b - 1] - t[a]:.4g} s"))
            excluded |= idle

    # stuck, clipped and frozen channels
    channels = [("force", f), ("displacement", x)] + ([("velocity", v)] if velocity_measured else [])
    for ch, values in channels:
        for kind, a, b, level in stuck_spans(values):
            if idle[a:b].all():
                continue  # a sensor at rest during an idle span: reported as idle
            span = f[a:b]
            if ch == "displacement" and kind == "stuck" and np.ptp(span) > 0.02 * f_range:
                kind, text = "frozen", (f"displacement frozen at {level:.6g} m while the force changes "
                                        f"by {np.ptp(span):.4g} N")
            elif kind == "clipped":
                text = f"{ch} at its clipping level {level:.6g}" + (
                    ": no fit sees a force beyond it, so a model's force there is an extrapolation"
                    if ch == "force" else "")
            else:
                text = f"{ch} stuck at {level:.6g} ({b - a} equal values)"
            findings.append(Finding(kind, ch, float(t[a]), float(t[b - 1]), b - a, text))
            excluded[a:b] = True
            if ch != "force":
                input_bad[a:b] = True

    # the dominant period again, on the longest stretch nothing has flagged: a frozen or clipped
    # span (a step in the displacement) would otherwise lengthen it and with it the derivative's
    # smoothing window below, and the velocity check would flag clean data everywhere
    if excluded.any() and (~excluded).sum() > 8:
        a_ok, b_ok = max(_runs(~excluded), key=lambda r: r[1] - r[0])
        if b_ok - a_ok > 8:
            period = 1.0 / dominant_frequency(t[a_ok:b_ok], x[a_ok:b_ok])

    # a fault's lurch: the velocity far beyond the test's own envelope next to a fault
    fault = input_bad | excluded & ~idle & ~held
    if fault.any():
        speed = np.abs(v if velocity_measured else _derivative(
            t, x, period, band_edge(t, np.gradient(x, t))))
        near = max(int(round(period / dt)), 1)
        # the test's own envelope, from the samples over a dominant period away from any fault:
        # a rig out of control swings the motion about beside its faults (the Dyke recording's
        # last half second, hundreds of samples at 3-4 times the test's speeds), and counted in
        # the percentile they would lift the envelope over the lurch they belong to
        quiet_ok = ~excluded & ~_within(fault, near)
        if quiet_ok.sum() < max(0.25 * n, 9):  # faults everywhere: the unflagged samples, as before
            quiet_ok = ~excluded
        envelope = float(np.percentile(speed[quiet_ok], 99.5)) if quiet_ok.sum() > 8 else 0.0
        if envelope > 0:
            fault_idx = np.flatnonzero(fault)
            for a, b in _runs(speed > EXCURSION_FACTOR * envelope):
                lo, hi = a, b
                while lo > 0 and speed[lo - 1] > envelope:
                    lo -= 1
                while hi < n and speed[hi] > envelope:
                    hi += 1
                k = np.searchsorted(fault_idx, lo)
                gap_to_fault = min(abs(int(fault_idx[j]) - c) for j in (k - 1, k) if 0 <= j < fault_idx.size
                                   for c in (lo, hi - 1))
                if gap_to_fault > near:
                    continue
                added = int((~excluded[lo:hi]).sum())
                findings.append(Finding("excursion", "velocity", float(t[lo]), float(t[hi - 1]), hi - lo,
                                        f"the velocity reaches {speed[a:b].max():.4g} m/s, "
                                        f"{speed[a:b].max() / envelope:.3g} times the test's 99.5th "
                                        f"percentile, next to a fault: the rig's lurch ({added} more "
                                        "samples excluded)"))
                excluded[lo:hi] = True
                input_bad[lo:hi] = True

    # velocity against the derivative of the displacement; offsets by cross-correlation. The
    # derivative's window follows the velocity's band too: over a random motion's slow drift
    # (its dominant period) it would smooth away what the velocity channel measures
    max_lag = max(int(round(0.1 * period / dt)), 2)
    ok = ~excluded
    edge = 0.0
    if ok.sum() > 8:  # on the longest unflagged stretch: a uniform grid, no fault in the spectrum
        a_ok, b_ok = max(_runs(ok), key=lambda r: r[1] - r[0])
        if b_ok - a_ok > 8:
            edge = band_edge(t[a_ok:b_ok], (v if velocity_measured else np.gradient(x, t))[a_ok:b_ok])
    deriv = _derivative(t, x, period, edge)
    # the lags are estimated on the longest unflagged stretch, away from its flagged neighbours by
    # a derivative's window: a frozen displacement span bends the derivative around it, and
    # stretches joined across a gap are no time series (a probe's 300 frozen samples had read as
    # the velocity lagging d(x)/dt by 6 ms, and moved the force's lag from 18 to 11 ms)
    stretch = _clean_stretch(~excluded, max_lag)
    if velocity_measured and np.ptp(deriv) > 0 and np.ptp(v) > 0:
        ok = ~excluded
        if stretch is not None:
            lag, gain, corr = _delay(v[stretch], deriv[stretch], max_lag)
        else:
            lag, gain, corr = _delay(np.where(ok, v, 0.0), np.where(ok, deriv, 0.0), max_lag)
        estimates.update(velocity_gain=gain, velocity_lag_s=lag * dt, velocity_correlation=corr)
        if not 0.8 < gain < 1.25:
            findings.append(Finding("velocity", "velocity", float(t[0]), float(t[-1]), 0,
                                    f"the velocity is {gain:.4g} times the derivative of the "
                                    "displacement (a unit or gain error)", excluded=False))
        if abs(lag) >= 2:
            findings.append(Finding("offset", "velocity", float(t[0]), float(t[-1]), 0,
                                    f"the velocity lags the derivative of the displacement by "
                                    f"{lag * dt:.4g} s ({lag:.1f} samples; peak correlation {corr:.3f})",
                                    excluded=False))
        # spans where the two depart: more than a quarter of the peak velocity, beyond the noise
        peak = float(np.percentile(np.abs(v[ok]), 99)) if ok.any() else 0.0
        shifted = np.roll(deriv, int(round(lag))) * (gain if 0.8 < gain < 1.25 else 1.0)
        apart = (np.abs(v - shifted) > 0.25 * peak) & ~excluded
        for a, b in _runs(apart):
            if b - a >= 3:
                findings.append(Finding("velocity", "velocity", float(t[a]), float(t[b - 1]), b - a,
                                        "the velocity departs from the derivative of the "
                                        "displacement by more than a quarter of its peak"))
                excluded[a:b] = True
                input_bad[a:b] = True
    ok = ~excluded
    if ok.sum() > 8 and np.ptp(f[ok]) > 0:
        fs, ds = (f[stretch], deriv[stretch]) if stretch is not None and np.ptp(f[stretch]) > 0 else (f[ok], deriv[ok])
        lag, corr = _lag(fs, ds, max_lag)
        estimates.update(force_velocity_lag_s=lag * dt, force_velocity_correlation=corr)
        if corr >= VELOCITY_LIKE_CORRELATION:
            # a damper's force has hysteresis (a yield force, a field, friction): one that follows
            # the velocity to the last per mille is a velocity channel read as force (a probe's
            # headerless file with its columns in another order fitted to 0.0025)
            findings.append(Finding(
                "velocity_like", "force", float(t[0]), float(t[-1]), 0,
                f"the force follows the velocity to a correlation of {corr:.4f} at a lag of "
                f"{1e3 * lag * dt:.3g} ms: no hysteresis at all, which no MR damper gives; a velocity "
                "channel read as force? (check the column order)", excluded=False))

    # polarity: a damper only dissipates, so a force doing net negative work is read with the
    # wrong sign against the motion; the motion is the displacement's derivative (a velocity
    # channel of the wrong sign is the velocity check's finding, not the force's)
    if ok.sum() > 8:
        work, share = net_work(t, f, deriv, ok)
        if np.isfinite(share):
            estimates["dissipated_work_share"] = share
            if share < -POLARITY_SHARE:
                findings.append(Finding(
                    "polarity", "force", float(t[0]), float(t[-1]), 0,
                    f"the force does net negative work on the motion ({work:.4g} J, {share:+.2f} of "
                    "its absolute work): a damper dissipates, so the force's sign is inverted against the "
                    "displacement (negate the force column, or the displacement and velocity)",
                    excluded=False))

    # units: amplitudes outside what any MR damper test produces
    plaus = {"amplitude": 0.5 * stroke,
             "peak_velocity": float(np.percentile(np.abs(v[ok] if ok.any() else v), 99.5)),
             "peak_force": float(np.percentile(np.abs(f[ok] if ok.any() else f), 99.5)),
             "sample_rate": 1.0 / dt}
    coil = _input_name(test)
    if coil is not None:
        plaus[f"peak_{coil}"] = float(np.nanmax(np.abs(_channel(test, coil))))
    units = {"amplitude": "m", "peak_velocity": "m/s", "peak_force": "N", "sample_rate": "Hz",
             "peak_voltage": "V", "peak_current": "A"}
    for key, value in plaus.items():
        lo, hi = PLAUSIBLE[key]
        estimates[key] = value
        if not lo <= value <= hi:
            findings.append(Finding("units", key.split("_")[-1] if key != "sample_rate" else "time",
                                    float(t[0]), float(t[-1]), 0,
                                    f"{key.replace('_', ' ')} {value:.4g} {units[key]} is outside "
                                    f"the plausible {lo:g}-{hi:g} {units[key]} of an MR damper test "
                                    "(wrong unit?)", excluded=False))

    # settling after unusable input spans: up to the next displacement reversal
    motion_fault = input_bad.copy()
    for a, b in _runs(input_bad):
        end = next_reversal(x, b) if b < n else n
        if end > b:
            motion_fault[b:end] = True
            added = int((~excluded[b:end]).sum())
            if added:
                excluded[b:end] = True
                findings.append(Finding("settling", "displacement", float(t[b]), float(t[end - 1]),
                                         added, "model state after an unusable input span: excluded "
                                         "up to the next displacement reversal"))
    # islands: a usable stretch shorter than one dominant period between two flagged spans, or
    # between one and the test's start or end, is no test of its own (its start is still
    # settling, its end already in the next fault; a fragment after a recording's last fault is
    # what is left of a rig out of control). Only next to a fault of the motion (an input
    # channel, a gap, a lurch, the settling after them): where only the force was flagged
    # (clipped at each peak, a dropout) the model ran through the same motion and the samples
    # between are data
    near = max(int(round(period / dt)), 1)
    for a, b in _runs(~excluded):
        beside_motion_fault = (a > 0 and motion_fault[a - 1]) or (b < n and motion_fault[b])
        if (a > 0 or b < n) and b - a < near and beside_motion_fault:
            excluded[a:b] = True
            where = ("between two flagged spans" if a > 0 and b < n
                     else "after the last flagged span" if a > 0 else "before the first flagged span")
            findings.append(Finding("island", "time", float(t[a]), float(t[b - 1]), b - a,
                                    f"{b - a} usable samples {where}, less than "
                                    f"one dominant period ({period:.3g} s)"))
    # a "spike" within a dominant period of a stuck, clipped or frozen span or a lurch (as for the
    # lurch itself) is the fault's, not a glitch of its own (the Dyke recording's force swings
    # between two clipped runs): its samples stay excluded, said by the fault's lines
    faulty = np.zeros(n, dtype=bool)
    for fd in findings:
        if fd.kind in ("stuck", "clipped", "frozen", "excursion"):
            faulty |= (t >= fd.t_start) & (t <= fd.t_end)
    if faulty.any():
        by_fault = _within(faulty, near)
        findings = [fd for fd in findings
                    if not (fd.kind == "spike" and by_fault[(t >= fd.t_start) & (t <= fd.t_end)].all())]
    findings.sort(key=lambda fd: (fd.t_start, fd.kind))
    return Screening(tuple(findings), ~excluded, estimates, name)


def screened(test: Any, prior: Sequence[Finding] = (), prior_excluded: np.ndarray | None = None,
             keep_flagged: bool = False) -> Any:
    """``test`` with its screening: ``mask`` set to the usable samples and the
    :class:`Screening` under ``metadata["screening"]``.

    With ``keep_flagged`` the findings are still reported but only samples that carry no
    measurement at all (missing values, filled by :func:`repair_samples`) are excluded.

    Parameters
    ----------
    test : DamperTest
        The test as read.
    prior : sequence of Finding
        Findings the reader already made (repaired missing values, dropped time stamps).
    prior_excluded : ndarray of bool, optional
        Samples the reader already knows to be unusable.
    keep_flagged : bool
        Report the findings but keep the flagged samples in fits and errors.
    """
    result = screen(test, prior, prior_excluded)
    usable = result.usable
    if keep_flagged:
        usable = np.ones(usable.size, dtype=bool) if prior_excluded is None else ~np.asarray(prior_excluded, bool)
    return dataclasses.replace(test, mask=None if usable.all() else usable, metadata={**test.metadata, "screening": result})


def keep_flagged(test: Any) -> Any:
    """``test`` with every screened sample back in (the report keeps the findings), except the
    samples that carry no measurement (missing values filled and held readings interpolated
    when read).

    Parameters
    ----------
    test : DamperTest
        A screened test.
    """
    result = test.metadata.get("screening")
    mask = None
    if result is not None:
        filled = filled_samples(result.findings, test.time)[1]
        mask = None if not filled.any() else ~filled
    return dataclasses.replace(test, mask=mask)


def filled_samples(findings: Sequence[Finding], time: np.ndarray) -> tuple[list, np.ndarray]:
    """The findings of samples that carry no measurement (missing values filled, held readings,
    spikes and lost slots interpolated when read: :func:`repair_samples`) and those samples.

    Parameters
    ----------
    findings : sequence of Finding
        A test's findings.
    time : ndarray (n,)
        The samples' times [s] (a part of the test's may be given: the findings over it count).

    Returns
    -------
    (list of Finding, ndarray of bool)
    """
    t = np.asarray(time, dtype=float)
    kept, filled = [], np.zeros(t.size, dtype=bool)
    for fd in findings:
        if fd.kind == "nan" or (fd.kind in _INTERPOLATED and fd.excluded):
            sel = (t >= fd.t_start) & (t <= fd.t_end)
            if sel.any():
                kept.append(fd)
                filled |= sel
    return kept, filled


def screening_of(test: Any) -> Screening:
    """The test's screening (from reading), or a fresh :func:`screen` of it.

    Parameters
    ----------
    test : DamperTest
        A test, screened when read or not.
    """
    result = getattr(test, "metadata", {}).get("screening")
    return result if isinstance(result, Screening) else screen(test)


def screening_key(test: Any) -> str:
    """The file a test was read from (its name when it was not read from a file), with the test's
    name when it is one span of that file (a coil-current level of a raw logger export,
    :func:`damper.io.data.split_utfsm_raw`): the key of its screening in reports and JSON.

    Parameters
    ----------
    test : DamperTest
        A test, read from a file or not.
    """
    name = getattr(test, "name", None) or "test"
    if not getattr(test, "source", None):
        return name
    span = (getattr(test, "metadata", None) or {}).get("span_s")
    return f"{Path(test.source).name} ({name})" if span else Path(test.source).name


def screening_summary(tests: Sequence[Any], keep_flagged: bool = False) -> dict:
    """The screening of each test as JSON: file name -> :meth:`Screening.to_json` plus
    ``kept_flagged`` and ``n_excluded`` (the samples left out of fits and errors as read).

    Parameters
    ----------
    tests : sequence of DamperTest
        Tests, screened when read or not (:func:`screening_of`).
    keep_flagged : bool
        The user kept the flagged samples (``--keep-flagged``).
    """
    out = {}
    for test in tests:
        doc = screening_of(test).to_json()
        doc["kept_flagged"] = bool(keep_flagged)
        doc["n_excluded"] = int(test.n_samples - test.usable.sum())
        units = (getattr(test, "metadata", None) or {}).get("file_units")
        if units:
            doc["file_units"] = dict(units)  # the columns read in a rig's units, converted to SI
        ignored = (getattr(test, "metadata", None) or {}).get("columns_ignored")
        if ignored:
            doc["columns_ignored"] = list(ignored)
        out[screening_key(test)] = doc
    return out


def units_line(units: dict) -> str:
    """The report's words for the columns a file gave in a rig's units (``metadata["file_units"]``
    of :func:`damper.io.data.read_csv`): ``read displacement in mm, converted to SI``.

    Parameters
    ----------
    units : dict of str to str
        Column name to the unit the file wrote.
    """
    return "read " + ", ".join(f"{k} in {u}" for k, u in units.items()) + ", converted to SI"


def unstated_line(test: Any, columns: Sequence[str]) -> str:
    """What a file whose header names no unit for ``columns`` was read as: their amplitudes in
    SI, so that a stroke in mm or a force in kN read as metres or newtons shows at a glance
    (amplitudes a real device may have pass the plausibility check)."""
    parts = []
    if "displacement" in columns:
        x = np.asarray(test.displacement, dtype=float)
        parts.append(f"stroke ±{0.5e3 * float(np.ptp(x)):.4g} mm")
        parts.append(f"peak velocity {1e3 * float(np.max(np.abs(test.velocity))):.4g} mm/s")
    if "force" in columns:
        parts.append(f"peak force {1e-3 * float(np.max(np.abs(test.force))):.4g} kN")
    return (f"no unit in the header for {', '.join(columns)}: read as SI ({', '.join(parts)}); "
            "if that is not the device, give the units in the header ([mm], [kN], ...)")


def screening_lines(tests: Sequence[Any], keep_flagged: bool = False) -> list[str]:
    """The screening findings as report lines (the estimated lags, one line per finding, one
    summary per test).

    Parameters
    ----------
    tests : sequence of DamperTest
        Tests, screened when read or not (:func:`screening_of`).
    keep_flagged : bool
        The user kept the flagged samples (``--keep-flagged``).
    """
    lines = []
    for test in tests:
        scr = screening_of(test)
        label = screening_key(test)
        units = (getattr(test, "metadata", None) or {}).get("file_units")
        if units:
            lines.append(f"screening {label}: {units_line(units)}")
        unstated = (getattr(test, "metadata", None) or {}).get("units_unstated")
        if unstated:
            lines.append(f"screening {label}: {unstated_line(test, unstated)}")
        ignored = (getattr(test, "metadata", None) or {}).get("columns_ignored")
        if ignored:
            lines.append(f"screening {label}: column(s) not used: {', '.join(ignored)} (the rig's other channels)")
        part = (getattr(test, "metadata", None) or {}).get("part")
        if part and not part.startswith("1 "):
            first = test.metadata.get("first_line")
            lines.append(f"screening {label}: the file's clock restarts at line {first}: part {part}, read as a "
                         "test of its own (a recording appended to the one before)")
        if scr.estimate_line():
            lines.append(f"screening {label}: estimated {scr.estimate_line()}")
        if not scr.findings:
            lines.append(f"screening {label}: nothing found")
            continue
        lines += [f"screening {label}: {line}" for line in finding_lines(scr.findings, kept=keep_flagged)]
        n_out = int(test.n_samples - test.usable.sum())
        lines.append(f"screening {label}: {n_out} of {test.n_samples} samples excluded from fit "
                     "and error" + (" (--keep-flagged: only missing values)" if keep_flagged else ""))
    return lines
