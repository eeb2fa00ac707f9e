"""A flaw found in a record: what :func:`records.checks.check_record` and
:func:`records.plausibility.check_plausibility` report."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["Flaw"]


@dataclass(frozen=True)
class Flaw:
    """One detected flaw.

    Attributes
    ----------
    kind : str
        ``"identical_components"``, ``"baseline_drift"``, ``"pga_mismatch"``, ``"duration_mismatch"`` or
        ``"implausible_..."`` (:func:`records.plausibility.check_plausibility`).
    message : str
        One line for people.
    component : int or None
        Component index (0-based) it concerns, if one.
    details : dict
        Numbers behind the message (plain JSON types).
    """

    kind: str
    message: str
    component: int | None = None
    details: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        return {"kind": self.kind, "message": self.message, "component": self.component, "details": self.details}
