"""The benchmark's superstructure and base: mass, stiffness, damping, bearing plan, in SI units.

Read from ``<shared>/benchmark/structure.json`` (the numbers of the benchmark's
``STRUC_run_this_to_get.m``, see ``shared/SOURCES.md``), which gives kN, m, s with
masses in t (= kN·s²/m) and rotational inertias in t·m². Everything here is converted
to SI on reading: masses ×10³ → kg, inertias ×10³ → kg·m², stiffness kN/m → N/m.

Model (Narasimhan et al. 2006, Part I)
----------------------------------------------------
Eight floors, each with three degrees of freedom (x, y, θ) at its centre of mass;
24 DOF ordered floor 1 → floor 8, (x, y, θ) per floor. The file's mass-normalised
mode shapes Φ are ordered floor 8 → floor 1 and are re-ordered on reading. From the
squared circular frequencies ω² and the modal damping ratio ζ = 5 %,

.. math::

    K = \\Phi^{-T} \\operatorname{diag}(\\omega^2) \\Phi^{-1}, \\qquad
    C = \\Phi^{-T} \\operatorname{diag}(2\\zeta\\omega) \\Phi^{-1},

exactly as the benchmark's own script does (its ``STRUC.mat`` K and C are reproduced to
machine precision).

A variant structure file may give another number of floors (field ``n_floors``, default 8, at
most :data:`MAX_FLOORS`): every per-floor field then has that many floors, the superstructure
``3 n_floors`` DOF, and the measurement vector ``3 + 3 n_floors`` accelerations
(:mod:`controllers.measurements`); the criteria, controllers and outputs follow. The mode
shapes keep their field name, ``mode_shapes_floor8_to_floor1``, at any height: rows top floor
first, three per floor. The floor masses and inertias give the diagonal M; that the floor
order is right is checked on reading by :math:`\\Phi^T M \\Phi \\approx I` (the file's
rounding leaves about 1 % off the identity; the reversed order is off by 11 %).

The base is a rigid slab with 3 DOF at its centre of mass (mass ``base_mass``, polar
inertia ``base_inertia``). Bearing (or device) *i* at plan position (x_i, y_i) relative to
the base centre of mass moves by :math:`T_i u_b` with

.. math::

    T_i = \\begin{bmatrix} 1 & 0 & -y_i \\\\ 0 & 1 & x_i \\end{bmatrix}, \\qquad
    H = \\sum_i T_i^T T_i .

Reduced order
-------------
:meth:`Superstructure.reduced` keeps the first *N* undamped modes Ψ (M-orthonormal
eigenvectors of (K, M), ordered by frequency): :math:`u_s \\approx \\Psi_N q`. The
superstructure matrices stay the physical 24×24 ones; the simulator and the linear model
use the generalised ones (:attr:`Superstructure.basis`, ``Mq = ΨᵀMΨ = I``,
``Kq = ΨᵀKΨ``, ``Cq = ΨᵀCΨ``, kept as a full block because C is not exactly diagonal in Ψ).
:meth:`Superstructure.mass_participation` reports how much of the mass each mode carries
in x, y and θ; the peak-response error against the full model on a record is reported by
:func:`benchmark.simulator.simulation.reduction_error`.

References
----------
Narasimhan S., Nagarajaiah S., Johnson E.A., Gavin H.P. (2006) Smart base-isolated
benchmark building. Part I: problem definition. Struct. Control Health Monit. 13:573–588.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import scipy.linalg

from benchmark.foundation.cache import FunctionCache
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.fields import check_field_names
from benchmark.foundation.paths import structure_file
from benchmark.foundation.textfile import read_text
from controllers.measurements import N_FLOORS  # the benchmark's 8 (the layout below the simulator owns it)

__all__ = ["Superstructure", "load_superstructure", "transformation", "location_matrix", "bearing_gaps",
           "N_FLOORS", "MAX_FLOORS", "DOF_NAMES"]

#: The most floors a structure file may have (a sanity bound on its size, not a limit of the method).
MAX_FLOORS = 40  # a 40-storey frame's fixed-base period, about 4 s, is within FUNDAMENTAL_PERIOD_RANGE
DOF_NAMES = ("x", "y", "theta")
_KILO = 1.0e3  # t → kg, kN → N, t·m² → kg·m²
_ORTHONORMALITY_TOLERANCE = 0.05  # max |ΦᵀMΦ − I| accepted (file rounding gives ~0.0125)


def transformation(xy: np.ndarray) -> np.ndarray:
    """Kinematic transformation matrices of points on the rigid base.

    Parameters
    ----------
    xy : array (n, 2)
        Plan positions (x, y) [m] relative to the base centre of mass.

    Returns
    -------
    T : array (n, 2, 3)
        :math:`T_i = [[1, 0, -y_i], [0, 1, x_i]]`, so that the point's displacement is
        :math:`T_i u_b` for base displacement :math:`u_b = (x, y, θ)`, and a force
        :math:`f_i` (x, y) at the point acts on the base as :math:`T_i^T f_i`.
    """
    xy = np.asarray(xy, dtype=float)
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"plan positions: expected an array of shape (n, 2), got {xy.shape}")
    n = xy.shape[0]
    T = np.zeros((n, 2, 3))
    T[:, 0, 0] = 1.0
    T[:, 1, 1] = 1.0
    T[:, 0, 2] = -xy[:, 1]
    T[:, 1, 2] = xy[:, 0]
    return T


def bearing_gaps(xy: np.ndarray) -> np.ndarray:
    """Distances [m] between every two plan positions ``xy`` (n, 2), ``inf`` on the diagonal
    (a position given twice, the plan's spacing, a device's nearest bearing).

    Parameters
    ----------
    xy : np.ndarray
        Plan positions (n, 2) [m].
    """
    xy = np.asarray(xy, dtype=float)
    gaps = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(gaps, np.inf)
    return gaps


def location_matrix(xy: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """Return :math:`H = \\sum_i w_i T_i^T T_i` (3×3) for plan positions ``xy`` (n, 2) [m].

    With unit weights this is the benchmark's location matrix (``STRUC.H``); with per-bearing
    stiffnesses as weights it is the base's stiffness matrix.

    Parameters
    ----------
    xy : np.ndarray
        Plan positions (n, 2) [m].
    weights : np.ndarray | None, optional
        Weight of each position; None: all 1.
    """
    T = transformation(xy)
    w = np.ones(len(T)) if weights is None else np.asarray(weights, dtype=float)
    return np.einsum("i,iaj,iak->jk", w, T, T)


@dataclass(frozen=True, eq=False)
class Superstructure:
    """The benchmark's superstructure, base and bearing plan, in SI units.

    Parameters
    ----------
    n_modes : int | None, optional
        Number of modes kept when reduced (:meth:`reduced`); None: the full 24-DOF model.
    _modes : tuple, optional
        Cache of the undamped modes (filled on use).

    Attributes
    ----------
    M, K, C : array (3 n_floors, 3 n_floors)
        Mass [kg, kg·m²], stiffness [N/m, N·m/rad ...] and damping [N·s/m ...] matrices,
        DOF order floor 1 → floor 8, (x, y, θ) per floor, relative to the base.
    R : array (3 n_floors, 3)
        Influence matrix (eight stacked 3×3 identities).
    storey_heights : array (n_floors,)
        Storey heights [m], storey 1 (base to floor 1) first.
    floor_heights : array (n_floors,)
        Height of floors 1..n_floors above the base [m].
    omega : array (3 n_floors,)
        Circular frequencies of the fixed-base modes as given by the benchmark [rad/s].
    phi : array (3 n_floors, 3 n_floors)
        The benchmark's mass-normalised mode shapes, rows re-ordered floor 1 → floor 8.
    base_mass : float
        Base slab mass [kg].
    base_inertia : float
        Base slab polar moment of inertia about its centre of mass [kg·m²].
    bearing_xy : array (92, 2)
        Bearing plan coordinates [m] relative to the base centre of mass.
    damping_ratio : float
        Modal damping ratio used to build C.
    basis : array (3 n_floors, n_q)
        Generalised coordinates of the superstructure, :math:`u_s = \\text{basis}\\, q`:
        the identity for the full model, the first N M-orthonormal modes for a reduced one.
    source : str
        The file the data were read from.
    linear_bearing : tuple of float, optional
        ``(k [N/m], c [N·s/m])`` per bearing of the ``linear`` isolation, from the file's
        ``fdz_linear_bearing`` (the benchmark's: 919.422 kN/m, 27.717 kN·s/m); None: those values.
    """

    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    R: np.ndarray
    storey_heights: np.ndarray
    floor_heights: np.ndarray
    omega: np.ndarray
    phi: np.ndarray
    base_mass: float
    base_inertia: float
    bearing_xy: np.ndarray
    damping_ratio: float
    basis: np.ndarray
    source: str = ""
    n_modes: int | None = None
    linear_bearing: tuple[float, float] | None = None
    _modes: tuple = field(default=(), repr=False)

    # ----------------------------------------------------------------------------- derived
    @property
    def n_dof(self) -> int:
        """Number of physical superstructure DOF (24 in the benchmark: 3 per floor)."""
        return self.M.shape[0]

    @property
    def n_floors(self) -> int:
        """Number of floors above the base (8 in the benchmark; a structure file may give another)."""
        return self.M.shape[0] // 3

    @property
    def n_q(self) -> int:
        """Number of generalised superstructure coordinates (``n_dof``, or N when reduced)."""
        return self.basis.shape[1]

    @property
    def is_reduced(self) -> bool:
        return self.n_modes is not None

    @property
    def m_base(self) -> np.ndarray:
        """Base mass matrix :math:`m = \\operatorname{diag}(m_b, m_b, I_b)` [kg, kg·m²]."""
        return np.diag([self.base_mass, self.base_mass, self.base_inertia])

    @property
    def T(self) -> np.ndarray:
        """Bearing transformation matrices :math:`T_i` (92, 2, 3), see :func:`transformation`."""
        return transformation(self.bearing_xy)

    @property
    def H(self) -> np.ndarray:
        """Location matrix :math:`H = \\sum_i T_i^T T_i` (3×3) of the bearings."""
        return location_matrix(self.bearing_xy)

    @property
    def n_bearings(self) -> int:
        return self.bearing_xy.shape[0]

    @property
    def total_mass(self) -> float:
        """Translational mass of the superstructure plus base [kg]."""
        return float(self.M[0::3, 0::3].trace() + self.base_mass)

    @property
    def Mq(self) -> np.ndarray:
        """Generalised mass :math:`\\Psi^T M \\Psi` (n_q × n_q)."""
        return self.basis.T @ self.M @ self.basis

    @property
    def Kq(self) -> np.ndarray:
        """Generalised stiffness :math:`\\Psi^T K \\Psi`."""
        return self.basis.T @ self.K @ self.basis

    @property
    def Cq(self) -> np.ndarray:
        """Generalised damping :math:`\\Psi^T C \\Psi`."""
        return self.basis.T @ self.C @ self.basis

    @property
    def Lq(self) -> np.ndarray:
        """Coupling to the base :math:`\\Psi^T M R` (n_q × 3)."""
        return self.basis.T @ self.M @ self.R

    def undamped_modes(self) -> tuple[np.ndarray, np.ndarray]:
        """Return (ω [rad/s] ascending, Ψ (24, 24) M-orthonormal) of the fixed-base (K, M).

        These are the exact modes of the K actually used (0.897/0.780/0.658 s first periods,
        Narasimhan et al. 2006, Part I); the file's Φ is their rounded version.
        """
        if self._modes:
            return self._modes
        w2, psi = scipy.linalg.eigh(self.K, self.M)
        # Sign convention: the largest component of each mode is positive (reproducible).
        idx = np.argmax(np.abs(psi), axis=0)
        psi = psi * np.sign(psi[idx, np.arange(psi.shape[1])])
        modes = (np.sqrt(np.maximum(w2, 0.0)), psi)
        object.__setattr__(self, "_modes", modes)
        return modes

    def mass_participation(self) -> np.ndarray:
        """Effective modal mass ratios of the fixed-base modes (24, 3) for x, y and θ.

        :math:`\\Gamma = \\Psi^T M R`; the ratio of mode *i* in direction *d* is
        :math:`\\Gamma_{id}^2 / (R^T M R)_{dd}`. Each column sums to 1 over all the modes (24 in the benchmark);
        the cumulative sum over the first N rows says how much mass a reduced model keeps.
        """
        _, psi = self.undamped_modes()
        gamma = psi.T @ self.M @ self.R
        total = np.diag(self.R.T @ self.M @ self.R)
        return gamma ** 2 / total

    def reduced(self, n_modes: int) -> "Superstructure":
        """Return the same superstructure described by its first ``n_modes`` undamped modes.

        Parameters
        ----------
        n_modes : int
            Modes kept, 1 ≤ n_modes ≤ n_dof (24 in the benchmark), lowest frequencies first.

        Returns
        -------
        Superstructure
            Same physical matrices; :attr:`basis` = Ψ[:, :n_modes] (M-orthonormal). Check the
            error with :meth:`mass_participation` and :func:`benchmark.simulator.simulation.reduction_error`.
        """
        if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) \
                or not 1 <= n_modes <= self.n_dof:
            raise InputError(f"n_modes: expected an integer in 1..{self.n_dof}, got {n_modes!r}")
        _, psi = self.undamped_modes()
        return replace(self, basis=psi[:, :int(n_modes)].copy(), n_modes=int(n_modes),
                       _modes=self._modes)

    def full(self) -> "Superstructure":
        """Return the full-order version (basis = identity)."""
        return replace(self, basis=np.eye(self.n_dof), n_modes=None, _modes=self._modes)

    def floor_slice(self, floor: int) -> slice:
        """Rows of floor ``floor`` (1..n_floors) in the superstructure's DOF vectors.

        Parameters
        ----------
        floor : int
            Floor number, 1..n_floors.
        """
        if not 1 <= floor <= self.n_floors:
            raise InputError(f"floor: expected 1..{self.n_floors}, got {floor}")
        return slice(3 * (floor - 1), 3 * floor)


def _not_a_number(value: Any) -> Any:
    """The first boolean or string inside ``value`` (nested lists), or None."""
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, (list, tuple)):
        for item in value:
            bad = _not_a_number(item)
            if bad is not None:
                return bad
    return None


def _field(data: dict, name: str, path: Path, shape: tuple | None = None,
           per_floor: str | None = None) -> np.ndarray:
    """Field ``name`` as a finite float array of ``shape``; ``per_floor``: the field's length
    follows n_floors, and a wrong length is said with that text (which n_floors was expected)."""
    if name not in data:
        raise InputError(f"{path}: field '{name}' missing")
    bad = _not_a_number(data[name])
    if bad is not None:
        # numpy reads true as 1 and "2051" as 2051: a typo would run as a building of other masses
        raise InputError(f"{path}: field '{name}' holds {bad!r}; expected numbers")
    try:
        arr = np.asarray(data[name], dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{path}: field '{name}' is not numeric ({exc})") from None
    if shape is not None and arr.shape != shape:
        if per_floor is not None and arr.ndim >= 1 and arr.shape[0] != shape[0]:
            raise InputError(f"{path}: field '{name}' has {arr.shape[0]} entries, expected {shape[0]}{per_floor}")
        raise InputError(f"{path}: field '{name}' has shape {arr.shape}, expected {shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(f"{path}: field '{name}' contains non-finite values")
    return arr


#: The fields of a structure file: those read, and the benchmark file's own notes and linear
#: bearing (read by :mod:`benchmark.simulator.isolation.linear`).
_STRUCTURE_FIELDS = ("n_floors", "omega_squared", "mode_shapes_floor8_to_floor1", "floor_mass", "floor_rot_inertia",
                     "modal_damping_ratio", "floor_height_above_base", "base_mass", "base_rot_inertia",
                     "bearing_xy", "mode_shapes_note", "bearing_note", "fdz_linear_bearing")


@lru_cache(maxsize=4)
def _load_cached(path_str: str, mtime: float) -> Superstructure:
    path = Path(path_str)
    try:
        data = json.loads(read_text(path, "benchmark structure file"))
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(data, dict):
        raise InputError(f"{path}: a JSON {type(data).__name__}; expected an object of named fields "
                         "(the benchmark's structure.json is one)")
    check_field_names(data, _STRUCTURE_FIELDS, str(path))
    floors = data.get("n_floors", N_FLOORS)
    if isinstance(floors, bool) or not isinstance(floors, int) or not 1 <= floors <= MAX_FLOORS:
        raise InputError(f"{path}: field 'n_floors' = {floors!r}; expected an integer number of floors "
                         f"above the base, 1..{MAX_FLOORS}")
    n = 3 * floors
    # a per-floor field of another length names n_floors (a file cut to fewer floors with n_floors
    # left at 8, or n_floors missing: the benchmark's 8 is the default); the floor masses first
    per_floor = f" for n_floors = {floors}" + ("" if "n_floors" in data
                                              else " (the default: give n_floors for another height)")
    floor_mass = _field(data, "floor_mass", path, (floors,), per_floor) * _KILO
    w2 = _field(data, "omega_squared", path, (n,), per_floor)
    if np.any(w2 <= 0):
        raise InputError(f"{path}: field 'omega_squared' must be positive")
    phi_file = _field(data, "mode_shapes_floor8_to_floor1", path, (n, n), per_floor)
    floor_inertia = _field(data, "floor_rot_inertia", path, (floors,), per_floor) * _KILO
    zeta = float(_field(data, "modal_damping_ratio", path, ()))
    heights = _field(data, "floor_height_above_base", path, (floors + 1,), per_floor)
    base_mass = float(_field(data, "base_mass", path, ())) * _KILO
    base_inertia = float(_field(data, "base_rot_inertia", path, ())) * _KILO
    bearing_xy = _field(data, "bearing_xy", path)
    if bearing_xy.ndim != 2 or bearing_xy.shape[1] != 2:
        raise InputError(f"{path}: field 'bearing_xy' has shape {bearing_xy.shape}, expected (n, 2)")
    centred = bearing_xy - bearing_xy.mean(axis=0) if bearing_xy.shape[0] else bearing_xy
    span = float(np.abs(centred).max()) if centred.size else 0.0
    if bearing_xy.shape[0] < 3 or np.linalg.matrix_rank(centred, tol=1e-6 * max(span, 1e-300)) < 2:
        # the base's plan (its corners' responses, J-criteria at the corners) needs an area
        raise InputError(f"{path}: field 'bearing_xy': {bearing_xy.shape[0]} bearing position(s) that span no "
                         "area (fewer than 3, or all on one line); expected the bearings of a plan")
    if np.any(np.diff(heights) <= 0):
        raise InputError(f"{path}: field 'floor_height_above_base' must increase")
    storeys = np.diff(heights)
    lo, hi = STOREY_HEIGHT_RANGE
    if np.any((storeys < lo) | (storeys > hi)):
        k = int(np.flatnonzero((storeys < lo) | (storeys > hi))[0])
        raise InputError(f"{path}: field 'floor_height_above_base': storey {k + 1} is {storeys[k]:g} m high; a "
                         f"storey is {lo:g}-{hi:g} m (heights in mm or cm?)")
    periods = 2.0 * np.pi / np.sqrt(w2)
    lo, hi = FUNDAMENTAL_PERIOD_RANGE
    if not lo <= float(periods.max()) <= hi:
        raise InputError(f"{path}: field 'omega_squared': the fixed-base fundamental period is "
                         f"{float(periods.max()):.4g} s; a building superstructure's is {lo:g}-{hi:g} s "
                         "(expected (rad/s)², "
                         "not Hz or Hz²)")
    if bearing_xy.shape[0] > 1:
        gaps = bearing_gaps(bearing_xy)
        if float(gaps.min()) < MIN_BEARING_SPACING:
            i, j = np.unravel_index(int(np.argmin(gaps)), gaps.shape)
            raise InputError(f"{path}: field 'bearing_xy': bearings {min(i, j) + 1} and {max(i, j) + 1} are "
                             f"{float(gaps.min()):.3g} m apart (a position given twice?); expected one bearing "
                             "per position")
    for name, values in (("floor_mass", floor_mass), ("floor_rot_inertia", floor_inertia),
                         ("base_mass", np.atleast_1d(base_mass)), ("base_rot_inertia", np.atleast_1d(base_inertia))):
        if np.any(values <= 0):
            raise InputError(f"{path}: field '{name}' must be positive, got {values[values <= 0][0] / _KILO:g} "
                             f"at entry {int(np.flatnonzero(values <= 0)[0])}")
    if not 0.0 <= zeta < 1.0:
        raise InputError(f"{path}: field 'modal_damping_ratio' must lie in [0, 1), got {zeta:g}")

    # File rows: row 3*(k-1)+j is floor 9-k. Re-order to floor 1 → floor 8.
    order = np.ravel([[3 * (floors - f) + j for j in range(3)] for f in range(1, floors + 1)])
    phi = phi_file[order]
    M = np.diag(np.ravel(np.column_stack([floor_mass, floor_mass, floor_inertia])))
    deviation = np.abs(phi.T @ M @ phi / _KILO - np.eye(n)).max()  # Φ is normalised in t
    if deviation > _ORTHONORMALITY_TOLERANCE:
        raise InputError(f"{path}: mode shapes are not mass-normalised against the floor masses "
                         f"(max |ΦᵀMΦ − I| = {deviation:.3g}); check the floor order of "
                         "'mode_shapes_floor8_to_floor1' and 'floor_mass'")
    omega = np.sqrt(w2)
    phi_inv = np.linalg.inv(phi)
    # Φ is normalised to the mass in t, so K = Φ⁻ᵀ ω² Φ⁻¹ comes out in kN/m: ×10³ → N/m.
    K = phi_inv.T @ np.diag(w2) @ phi_inv * _KILO
    C = phi_inv.T @ np.diag(2.0 * zeta * omega) @ phi_inv * _KILO
    K = 0.5 * (K + K.T)
    C = 0.5 * (C + C.T)
    R = np.tile(np.eye(3), (floors, 1))
    arrays = dict(M=M, K=K, C=C, R=R, storey_heights=np.diff(heights), floor_heights=heights[1:],
                  omega=omega, phi=phi / np.sqrt(_KILO), bearing_xy=bearing_xy)
    for arr in arrays.values():
        arr.setflags(write=False)
    basis = np.eye(n)
    basis.setflags(write=False)
    return Superstructure(**arrays, base_mass=base_mass, base_inertia=base_inertia,
                          damping_ratio=zeta, basis=basis, source=str(path),
                          linear_bearing=_linear_bearing(data, path))


def _linear_bearing(data: dict, path: Path) -> tuple[float, float] | None:
    """``(k [N/m], c [N·s/m])`` of the file's ``fdz_linear_bearing`` (kN/m, kN·s/m), or None."""
    entry = data.get("fdz_linear_bearing")
    if entry is None:
        return None
    where = f"{path}: field 'fdz_linear_bearing'"
    if not isinstance(entry, dict):
        raise InputError(f"{where}: expected an object with k_per_bearing_kN_per_m and c_per_bearing_kNs_per_m")
    check_field_names(entry, ("k_per_bearing_kN_per_m", "c_per_bearing_kNs_per_m", "note"), where)
    values = []
    for key in ("k_per_bearing_kN_per_m", "c_per_bearing_kNs_per_m"):
        value = entry.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
            raise InputError(f"{path}: field 'fdz_linear_bearing.{key}' = {value!r}; expected a non-negative number")
        values.append(float(value) * _KILO)
    if values[0] <= 0:
        raise InputError(f"{path}: field 'fdz_linear_bearing.k_per_bearing_kN_per_m' must be positive (a bearing "
                         "carries the building)")
    return values[0], values[1]


#: Storey heights a structure file may give [m] (a file in mm or cm falls outside).
STOREY_HEIGHT_RANGE = (1.0, 20.0)
#: Fixed-base fundamental periods a structure file may give [s]: an 8-storey superstructure's
#: (the benchmark's: 0.89 s; the rule of thumb 0.1 s per storey; a variant five times as flexible
#: still fits); omega² given as frequencies in Hz (5.9 s) or in Hz² (5.6 s) falls outside.
FUNDAMENTAL_PERIOD_RANGE = (0.05, 5.0)
#: Closest two bearings may stand [m].
MIN_BEARING_SPACING = 0.05


#: Superstructures read from their files, by path and modification time.
SUPERSTRUCTURE_FILES = FunctionCache("simulator.superstructure_files", _load_cached)


def load_superstructure(path: str | os.PathLike | None = None) -> Superstructure:
    """Read the benchmark superstructure from ``structure.json`` and convert it to SI.

    Parameters
    ----------
    path : path-like, optional
        The ``structure.json`` file; defaults to :func:`benchmark.foundation.paths.structure_file`
        (``$SBIB_SHARED/benchmark/structure.json``).

    Returns
    -------
    Superstructure
        Full-order (24 DOF) superstructure with its base and bearing plan, SI units.

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        A field is missing, has the wrong shape, or the floor order fails ΦᵀMΦ ≈ I.
    """
    p = structure_file(path)
    try:
        mtime = p.stat().st_mtime
    except OSError as exc:  # pragma: no cover - race with deletion
        raise DataNotFoundError(f"benchmark structure file {p}: {exc}") from None
    return _load_cached(str(p.resolve()), mtime)
