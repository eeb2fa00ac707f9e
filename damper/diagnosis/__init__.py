"""The residual loop: fit a base model, trace the residual, add library effects while they pay.

Modules: :mod:`~damper.diagnosis.dataset` (tests -> motions, forces, training and held-out
samples), :mod:`~damper.diagnosis.trace` (where the residual lives, whiteness),
:mod:`~damper.diagnosis.base_fit` (the base model's fit), :mod:`~damper.diagnosis.selection`
(matching the residual against the effect library, held-out BIC),
:mod:`~damper.diagnosis.loop` (the whole loop, :func:`diagnose`) and
:mod:`~damper.diagnosis.report` (Markdown report and plots).
"""

from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.loop import Diagnosis, diagnose
from damper.diagnosis.trace import ResidualTrace, trace_residual

__all__ = ["DiagnosisData", "Diagnosis", "diagnose", "ResidualTrace", "trace_residual"]
