"""One row of the ``sbib bench`` table (:mod:`benchmark.applications.speed`,
:mod:`benchmark.applications.speed_diagnose`)."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["BenchCase"]


@dataclass
class BenchCase:
    """One row of the benchmark table.

    Attributes
    ----------
    case : str
        Case name.
    project_s : float or None
        Time of the project's code [s] (None: not measured).
    reference_s : float or None
        Time of the reference [s] (scipy ``solve_ivp`` where there is one).
    ratio : float or None
        ``reference_s / project_s``.
    max_relative_difference : float or None
        Largest relative difference of the compared quantities (peaks) [-].
    target : str
        The target, in words.
    met : bool or None
        Whether the target is met (None: no target or not measured).
    vs_floor : float or None
        ``project_s`` over the linear floor measured in the same process
        (:mod:`benchmark.applications.linear_floor`), or for ``suite-efficiency`` the parallel time over the
        ideal one: the ratio the target is stated in.
    note : str
        What was measured, or why it was not.
    details : dict
        Extra numbers (JSON-serialisable).
    """

    case: str
    project_s: float | None = None
    reference_s: float | None = None
    ratio: float | None = None
    max_relative_difference: float | None = None
    target: str = ""
    met: bool | None = None
    vs_floor: float | None = None
    note: str = ""
    details: dict = field(default_factory=dict)
