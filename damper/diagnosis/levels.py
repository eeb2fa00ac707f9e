"""The force level of each test against the final model: does the device change between tests?

A model of the motion and the coil input predicts the same force for the same motion whenever it
is run. A device does not always give it: MR fluid heats over a test campaign (its viscosity and
yield stress fall), a coil's resistance rises with it, seals wear in. Tests recorded minutes or
days apart then differ in force level by a few per cent to tens of per cent, which no term of the
motion predicts and which the residual trace finds in no variable. On the UTFSM tests the final
model's held-out error was 0.098 / 0.080 / 0.073 at 0 / 0.5 / 1 A, and 0.088 / 0.070 / 0.067
with one level per test (docs/diagnosis.md, "What the UTFSM residual is"): part of what looked
like a missing effect was the device itself, test to test.

For each test with both a training and a held-out part, the level is the least-squares factor
:math:`a_i = \\hat F \\cdot F / \\hat F \\cdot \\hat F` of the final model's force over the test's
**training** samples (never the held-out ones), and the held-out error is recomputed with each
test's force model scaled by its level. A finding when the tests' levels spread by at least
:data:`LARGE_SPREAD` (tests of one device at one input ten per cent apart: far beyond a load
cell's repeatability), or by at least :data:`LEVEL_SPREAD` while the held-out error with them
falls below :data:`ERROR_SHARE` of the error as scored. It is a diagnostic: nothing is refitted
and the loop's errors stay as scored.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

__all__ = ["force_levels", "level_lines", "LARGE_SPREAD", "LEVEL_SPREAD", "ERROR_SHARE", "MIN_TRAIN"]

#: Levels spread by this much (largest minus smallest) are a finding ...
LARGE_SPREAD = 0.10
#: ... as are levels spread by this much ...
LEVEL_SPREAD = 0.05
#: ... that take the held-out error below this share of it.
ERROR_SHARE = 0.9
#: Fewest training samples a test's level is estimated from.
MIN_TRAIN = 20


def force_levels(names: Sequence[str], forces: Sequence[np.ndarray], predicted: Sequence[np.ndarray],
                train: Sequence[np.ndarray], heldout: Sequence[np.ndarray]) -> dict | None:
    """Each test's force level against the final model and the held-out error with them (module
    docstring); None with fewer than two tests that have both parts.

    Parameters
    ----------
    names : sequence of str
        Test names.
    forces, predicted : sequence of ndarray
        Measured force and the final model's force of each test [N].
    train, heldout : sequence of ndarray of bool
        Each test's training and held-out samples (those that count).

    Returns
    -------
    dict or None
        ``levels`` (name -> factor), ``spread``, ``error`` (held-out, as scored: every test with
        held-out samples), ``error_with_levels`` (a test whose level cannot be estimated keeps
        1), ``finding``.
    """
    levels: dict[str, float] = {}
    num = num_levels = den = 0.0
    for name, f, g, tr, ho in zip(names, forces, predicted, train, heldout):
        tr, ho = np.asarray(tr, dtype=bool), np.asarray(ho, dtype=bool)
        if not ho.any():
            continue
        # a test whose level cannot be estimated keeps the model's (1): the sums stay the loop's
        gg = float(g[tr] @ g[tr]) if int(tr.sum()) >= MIN_TRAIN else 0.0
        a = float(g[tr] @ f[tr]) / gg if gg > 0 else math.nan
        if math.isfinite(a) and a > 0:
            levels[name] = a
        else:
            a = 1.0
        r, r_level = f[ho] - g[ho], f[ho] - a * g[ho]
        num += float(r @ r)
        num_levels += float(r_level @ r_level)
        den += float(f[ho] @ f[ho])
    if len(levels) < 2 or not den > 0:
        return None
    values = np.array(list(levels.values()))
    spread = float(values.max() - values.min())
    error, with_levels = math.sqrt(num / den), math.sqrt(num_levels / den)
    return {"levels": levels, "spread": spread, "error": error, "error_with_levels": with_levels,
            "finding": bool(spread >= LARGE_SPREAD or (spread >= LEVEL_SPREAD and with_levels < ERROR_SHARE * error))}


def level_lines(found: dict | None) -> list[tuple[str, bool]]:
    """One sentence for the output and the report, with whether it is a finding.

    Parameters
    ----------
    found : dict or None
        :func:`force_levels`' result (``Diagnosis.force_levels``).
    """
    if not found:
        return []
    levels = found["levels"]
    lo = min(levels, key=levels.get)
    hi = max(levels, key=levels.get)
    text = (f"force level by test against the final model (each test's training part): "
            f"{levels[lo]:.3f} ({lo}) to {levels[hi]:.3f} ({hi}); with one level per test the held-out "
            f"error would be {found['error']:.4f} -> {found['error_with_levels']:.4f}")
    if found["finding"]:
        text += (": the tests differ in force level by more than the model's error explains: a device that "
                 "changed between tests (as MR fluid does with temperature), which no model of the motion "
                 "predicts, or a term missing from the model that grows with a test's amplitude or frequency")
    return [(text, found["finding"])]
