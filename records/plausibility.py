"""Is this a physically possible ground motion? Checks that catch wrong units and wrong time steps.

A record read in the wrong units (cm/s² read as m/s² multiplies everything by 100) or with
the wrong time step still runs, and the simulation then reports tens of metres of base
displacement. These checks compare the record with the largest ground motions ever recorded,
with margin, so that a real record never trips them and a unit or time-step mistake does:

======================  ===========  ==================================================================
quantity                flagged at   what has been recorded
======================  ===========  ==================================================================
PGA (one horizontal     > 5 g        the largest recorded accelerations are about 4 g (three-component
component)                           vector 4.36 g, vertical 3.87 g, station IWTH25 in the 2008
                                     Iwate–Miyagi earthquake, Aoi et al. 2008) and about 2.7 g
                                     horizontal (K-NET MYG004, 2011 Tohoku)
PGV after a baseline    > 5 m/s      the largest recorded velocities are about 3 m/s (TCU068 and
                                     TCU052, 1999 Chi-Chi; this repository's ``jiji`` record: 2.8 and
correction                           3.1 m/s, :mod:`records.catalogue`)
PGD after a baseline    > 10 m       the largest recorded ground displacements are a few metres (TCU068,
correction                           Chi-Chi, beside a surface rupture of up to about 9 m, Boore 2001;
                                     ``jiji`` here: 4.5 and 3.9 m after the correction)
time step dt            > 0.05 s     strong-motion records are sampled at 50–200 samples per second (NGA-
                                     West2 files: dt = 0.005–0.02 s, Ancheta et al. 2014); at 0.05 s the
                                     Nyquist frequency, 10 Hz, already cuts off the content that makes
                                     the PGA
time step dt            < 1e-4 s     no accelerograph samples faster than 10 kHz; a time in ms read as s
                                     gives this
duration n·dt           > 1000 s     the longest strong-motion files (K-NET, 2011 Tohoku) last 300 s
duration n·dt           < 5 s        triggered accelerographs keep 10-20 s of pre-event memory and the
                                     shortest NGA-West2 files last about 10 s: a truncated file, or a
                                     time step given 10x too small
======================  ===========  ==================================================================

Velocity and displacement are checked after :func:`records.baseline.baseline_correct` (cubic
baseline), because an uncorrected record's displacement drifts without bound (``jiji`` reaches
49 m) and an offset in the acceleration ramps the velocity up; that drift is reported by
:func:`records.checks.check_baseline_drift` instead. A record read
100 times too large keeps its shape, so all amplitude checks fire together; the message says
which units were assumed and how to give others (``--units``, ``--dt``).

References
----------
Aoi, S., Kunugi, T. & Fujiwara, H. (2008) Trampoline effect in extreme ground motion.
Science 322, 727–730. Boore, D. M. (2001) Effect of baseline corrections on displacements and
response spectra for several recordings of the 1999 Chi-Chi, Taiwan, earthquake. Bull. Seism.
Soc. Am. 91(5), 1199–1211. Ancheta, T. D. et al. (2014) NGA-West2 database. Earthquake
Spectra 30(3), 989–1005.
"""

from __future__ import annotations

from records.flaws import Flaw
from records.record import STANDARD_GRAVITY, Record
from records.record import units_assumed
from records.baseline import baseline_correct

__all__ = ["check_plausibility", "MAX_PGA_G", "MAX_PGV_M_S", "MAX_PGD_M", "MAX_DT_S", "MIN_DT_S",
           "MAX_DURATION_S", "MIN_DURATION_S"]

#: Largest plausible PGA of one horizontal component [g] (module docstring).
MAX_PGA_G = 5.0
#: Largest plausible PGV [m/s].
MAX_PGV_M_S = 5.0
#: Largest plausible PGD after baseline correction [m].
MAX_PGD_M = 10.0
#: Coarsest plausible time step [s].
MAX_DT_S = 0.05
#: Finest plausible time step [s].
MIN_DT_S = 1e-4
#: Longest plausible record [s].
MAX_DURATION_S = 1000.0
#: Shortest plausible record [s].
MIN_DURATION_S = 5.0


def _units_hint(record: Record) -> str:
    origin = str(record.metadata.get("units_from", ""))
    if origin in ("header", "file", "file comments", "file header") or origin.startswith("header"):
        # --units may not contradict a unit the file states: the file itself must be corrected
        return (f"values read as {units_assumed(record)}; the file states that unit: if its values are in "
                "another one, correct the file (--units cannot override what a file states)")
    return f"values read as {units_assumed(record)}; wrong units? (give --units, e.g. cm/s2 or g)"


def check_plausibility(record: Record) -> list[Flaw]:
    """Flag amplitudes and time steps no recorded earthquake has had (thresholds in the module docstring).

    Parameters
    ----------
    record : Record
        The record, in m/s².

    Returns
    -------
    list of Flaw
        Kinds ``implausible_pga``, ``implausible_velocity``, ``implausible_displacement``
        (one per component), ``implausible_time_step`` and ``implausible_duration``.
    """
    flaws: list[Flaw] = []
    name = record.name
    for c, pga in enumerate(record.pga / STANDARD_GRAVITY):
        if pga > MAX_PGA_G:
            flaws.append(Flaw("implausible_pga",
                              f"{name} {record.labels[c]}: PGA {pga:.3g} g is implausible (no recorded horizontal "
                              f"motion exceeds about 3 g; flagged above {MAX_PGA_G:g} g); {_units_hint(record)}",
                              c, {"pga_g": float(pga), "limit_g": MAX_PGA_G}))
    if record.n_samples < 6:  # too short for the cubic baseline: amplitudes of PGA only
        corrected = None
    else:
        corrected = baseline_correct(record)
    for c, pgv in enumerate(corrected.pgv if corrected is not None else ()):
        if pgv > MAX_PGV_M_S:
            flaws.append(Flaw("implausible_velocity",
                              f"{name} {record.labels[c]}: PGV {pgv:.3g} m/s (after baseline correction) is "
                              f"implausible (recorded motions reach about 3 m/s; flagged above {MAX_PGV_M_S:g} m/s); "
                              f"{_units_hint(record)}",
                              c, {"pgv_corrected_m_s": float(pgv), "limit_m_s": MAX_PGV_M_S}))
    if corrected is not None:
        for c, value in enumerate(corrected.pgd):
            if value > MAX_PGD_M:
                flaws.append(Flaw("implausible_displacement",
                                  f"{name} {record.labels[c]}: ground displacement {value:.3g} m even after baseline "
                                  f"correction is implausible (recorded motions reach a few metres; flagged above "
                                  f"{MAX_PGD_M:g} m); {_units_hint(record)}",
                                  c, {"pgd_corrected_m": float(value), "limit_m": MAX_PGD_M}))
    if record.dt > MAX_DT_S or record.dt < MIN_DT_S:
        flaws.append(Flaw("implausible_time_step",
                          f"{name}: time step {record.dt:g} s is implausible for a strong-motion record (they are "
                          f"sampled every {MIN_DT_S:g} to {MAX_DT_S:g} s, usually 0.005-0.02 s); "
                          f"{record.n_samples} samples last {record.duration:g} s; wrong time step? (give --dt)",
                          None, {"dt_s": record.dt, "duration_s": record.duration}))
    if record.duration > MAX_DURATION_S:
        flaws.append(Flaw("implausible_duration",
                          f"{name}: {record.n_samples} samples at dt = {record.dt:g} s last {record.duration:g} s, longer "
                          f"than any strong-motion record (flagged above {MAX_DURATION_S:g} s); wrong time step? "
                          "(give --dt)",
                          None, {"dt_s": record.dt, "duration_s": record.duration}))
    if record.duration < MIN_DURATION_S:
        flaws.append(Flaw("implausible_duration",
                          f"{name}: {record.n_samples} samples at dt = {record.dt:g} s last {record.duration:g} s, shorter "
                          f"than any strong-motion record (flagged below {MIN_DURATION_S:g} s); a truncated file "
                          "or a wrong time step? (give --dt)",
                          None, {"dt_s": record.dt, "duration_s": record.duration}))
    return flaws
