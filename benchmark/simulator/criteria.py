"""The evaluation criteria J1–J9: one table of definitions used by every table, figure and JSON.

Each criterion has a name, a formula, what it is normalised by (the uncontrolled run, or the
controlled run itself), its source, and, where the project had to decide something the source
leaves open, that decision. :mod:`benchmark.simulator.evaluation` computes them; everything that *shows*
J's takes its labels and its key from here (docs/criteria.md is the same table in prose).

Notation: ‖·‖ is the x–y resultant at the centre of mass; ``max_t`` over the whole record; a
subscript 0 marks the uncontrolled run (same building, isolation, record and orientation, no
devices); ``rms`` is the root mean square over time.

References
----------
Narasimhan S., Nagarajaiah S., Johnson E.A., Gavin H.P. (2006) Smart base-isolated benchmark
building. Part I: problem definition. Struct. Control Health Monit. 13:573–588 (section
"Evaluation criteria").
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

__all__ = ["Criterion", "CRITERIA", "J_NAMES", "SOURCE", "RATIO_TO_UNCONTROLLED", "is_ratio",
           "axis_label", "key_lines", "key_json", "key_text"]

SOURCE = "Narasimhan et al. (2006), Part I, 'Evaluation criteria'"
#: what a ratio criterion means on a plot axis
RATIO_TO_UNCONTROLLED = "ratio to uncontrolled (1 = no change)"


@dataclass(frozen=True)
class Criterion:
    """One evaluation criterion (see the module docstring).

    Parameters
    ----------
    key : str
        Criterion key (``"J1"`` … ``"J9"``).
    name : str
        Short name (e.g. ``"peak base shear"``).
    formula : str
        Its formula, as text.
    normalised_by : str
        What it is divided by (the uncontrolled run's peak, …).
    source : str
        Where it is defined (paper, section).
    choice : str, optional
        A choice this project made in computing it, if any.
    """

    key: str
    name: str
    formula: str
    normalised_by: str          # "uncontrolled run" or "controlled run"
    source: str
    choice: str = ""            # the project's own decision, where the source leaves one open

    @property
    def description(self) -> str:
        """One line: the name and what it is divided by."""
        return (f"{self.name} / uncontrolled" if self.normalised_by == "uncontrolled run"
                else f"{self.name} (controlled run)")


_UNVERIFIED = ("the source's numbering and definition of J6 and J9 could not be checked "
               "against the paper (see docs/criteria.md); the project chose this "
               "definition and keeps it fixed")

CRITERIA: dict[str, Criterion] = {c.key: c for c in (
    Criterion("J1", "peak base shear", "max_t ‖V_0(t)‖ / max_t ‖V_0(t)‖₀  (bearings + devices)",
              "uncontrolled run", SOURCE),
    Criterion("J2", "peak first-storey (structure) shear",
              "max_t ‖V_1(t)‖ / max_t ‖V_1(t)‖₀,  V_1 = Rᵀ(K u_s + C u̇_s)", "uncontrolled run", SOURCE),
    Criterion("J3", "peak base displacement", "max_t ‖u_b(t)‖ / max_t ‖u_b(t)‖₀",
              "uncontrolled run", SOURCE),
    Criterion("J4", "peak inter-storey drift ratio", "max_{t,f} ‖d_f(t)‖/h_f / (same)₀",
              "uncontrolled run", SOURCE, "floor 1's drift is relative to the base"),
    Criterion("J5", "peak absolute floor acceleration", "max_{t,f} ‖a_f(t)‖ / (same)₀, every floor",
              "uncontrolled run", SOURCE),
    Criterion("J6", "peak total device force over peak base shear",
              "max_t ‖Σ_j f_d,j(t)‖ / max_t ‖V_0(t)‖  (both of the controlled run)",
              "controlled run", SOURCE, "normalised by the controlled run's base shear; " + _UNVERIFIED),
    Criterion("J7", "RMS base displacement", "rms_t ‖u_b(t)‖ / (same)₀", "uncontrolled run", SOURCE),
    Criterion("J8", "RMS absolute floor acceleration (largest floor)",
              "max_f rms_t ‖a_f(t)‖ / (same)₀", "uncontrolled run", SOURCE,
              "the largest floor's RMS (not the RMS over all floors)"),
    Criterion("J9", "device energy over input energy",
              "E_device(T) / E_input(T)  (controlled run, at the end of the record)",
              "controlled run", SOURCE, _UNVERIFIED),
)}

J_NAMES: tuple[str, ...] = tuple(CRITERIA)


def is_ratio(key: str) -> bool:
    """Whether criterion ``key`` is a ratio to the uncontrolled run (1 = no change).

    Parameters
    ----------
    key : str
        Criterion key (``"J1"`` … ``"J9"``).
    """
    return CRITERIA[key].normalised_by == "uncontrolled run"


def axis_label(key: str) -> str:
    """What the values of criterion ``key`` mean on a plot axis.

    Parameters
    ----------
    key : str
        Criterion key (``"J1"`` … ``"J9"``).
    """
    c = CRITERIA[key]
    return RATIO_TO_UNCONTROLLED if is_ratio(key) else f"{c.name} [-]"


def key_lines(formulas: bool = True) -> list[str]:
    """The key as text lines, one per criterion (for tables and figure captions).

    Parameters
    ----------
    formulas : bool, optional
        Include each criterion's formula.
    """
    lines = []
    for c in CRITERIA.values():
        norm = "ratio to uncontrolled" if is_ratio(c.key) else "controlled run only"
        text = f"{c.key}: {c.name} ({norm})"
        if formulas:
            text += f" = {c.formula}"
        lines.append(text)
    lines.append(f"Source: {SOURCE}; the project's own choices: docs/criteria.md")
    return lines


def key_text(formulas: bool = True) -> str:
    """:func:`key_lines` joined by newlines.

    Parameters
    ----------
    formulas : bool, optional
        Include each criterion's formula.
    """
    return "\n".join(key_lines(formulas))


def key_json() -> dict:
    """``{"J1": {name, formula, normalised_by, source, choice}, ...}`` for JSON and HDF5 output."""
    out = {}
    for k, c in CRITERIA.items():
        entry = asdict(c)
        entry.pop("key")
        out[k] = entry
    return out
