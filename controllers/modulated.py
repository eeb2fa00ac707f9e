"""Continuously modulated clipped-optimal control: intermediate voltages (Yoshida & Dyke 2004).

The same H2/LQG design and Kalman filter as :mod:`controllers.clipped_optimal`; the voltage
is scaled with the desired force instead of switching between 0 and V_max:

.. math::

    v_i = V_{max} \\min\\left(1, \\frac{|f_{c,i}|}{f_{0,i}}\\right) H\\big((f_{c,i} - f_i) f_i\\big),

with :math:`f_{0,i}` the device's force capacity at :math:`V_{max}` (law 2 of
:mod:`controllers.compiled`). Commanding less than full voltage when little force is wanted
avoids the force jumps (and acceleration spikes) of the bang-bang rule.

References
----------
Yoshida O., Dyke S.J. (2004) Seismic control of a nonlinear, asymmetric building with
magnetorheological dampers. J. Eng. Mech. 130(4):386–392.
"""

from __future__ import annotations

import numpy as np

from controllers.base import ControlContext, register_controller
from controllers.clipped_optimal import ClippedOptimal, LQGDesign
from controllers.compiled import LAW_MODULATED

__all__ = ["ModulatedClippedOptimal"]


@register_controller
class ModulatedClippedOptimal(ClippedOptimal):
    """Clipped-optimal with voltages proportional to the desired force (``modulated``).

    Parameters are those of :class:`~controllers.clipped_optimal.ClippedOptimal`; the force
    capacity :math:`f_0` is the design's force scale (``LQGWeights.force_scale`` or the device's
    peak force at maximum voltage).

    Parameters
    ----------
    weights : LQGWeights, optional
        Design weights (defaults in :class:`~controllers.clipped_optimal.LQGWeights`); they also define Q.
    plant : LinearPlant, optional
        Design model; default: :func:`controllers.plant.building_plant` of the run's building.
    voltage : float, optional
        Commanded "on" voltage [V]; default: each device's maximum.
    check_fit : bool, optional
        Compute the estimator fit at design time (shown in :meth:`LQGDesign.report`).
    dead_band : float, optional
        Dead band on the desired force as a fraction of the force scale f₀, in [0, 1) (default
        :data:`~controllers.clipped_optimal.DEFAULT_DEAD_BAND`).
    """

    name = "modulated"
    law_id = LAW_MODULATED

    def law_parameters(self, design: LQGDesign, context: ControlContext) -> np.ndarray:
        """Force capacity per device [N].

        Parameters
        ----------
        design : LQGDesign
            The LQG design this controller made (:meth:`make_design`).
        context : ControlContext
            The run's control context (:class:`controllers.base.ControlContext`: design model, device count,
            control step).
        """
        return design.force_scale.copy()
