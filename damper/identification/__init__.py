"""Identification of MR damper models from periodic tests (Ikhouane–Rodellar, Rodríguez, Bahar et al. 2009).

Modules: :mod:`~.cycles` (cycles, limit cycle, branches, excitation check),
:mod:`~.closed_form` (closed-form steps, design points), :mod:`~.refine` (joint nonlinear least
squares with uncertainty), :mod:`~.identify` (the chain for one test), :mod:`~.metrics`
(error measures), :mod:`~.voltage_grid` (voltage grid and voltage laws), :mod:`~.voltage_lag`
(field lag), :mod:`~.validation` (inside earthquake runs, errors by field regime), :mod:`~.ceiling` (the
best each model form reaches on an earthquake's damper motion), :mod:`~.measured` (measured files),
:mod:`~.study` (``sbib identify``), :mod:`~.plots`.

The device under test is always handed in (a model instance or a registered name) and reached
only through :mod:`damper.lab.laboratory` or the building's recorded histories.
"""

from damper.identification.closed_form import MODEL_FORMS, PARAMETER_NAMES, ClosedFormResult, closed_form
from damper.identification.identify import Identification, identify, identify_arrays
from damper.identification.metrics import force_errors
from damper.identification.refine import RefinedFit, refine

__all__ = ["MODEL_FORMS", "PARAMETER_NAMES", "ClosedFormResult", "closed_form", "Identification",
           "identify", "identify_arrays", "force_errors", "RefinedFit", "refine"]
