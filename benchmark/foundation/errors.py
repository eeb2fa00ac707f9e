"""Exception classes shared by every package of the project.

Every error a user can cause (a malformed file, an option out of range, an
inadmissible parameter) is an :class:`InputError` whose message names the file,
line or field and what was expected; the CLI prints it on one line and exits
with status 2. A numerical failure (state blow-up, NaN, a sub-stepping tolerance
that cannot be met) is a :class:`NumericalError` that carries the time and the
state that failed; the CLI exits with status 3.
"""

from __future__ import annotations

__all__ = [
    "SbibError",
    "InputError",
    "ParameterError",
    "DataNotFoundError",
    "UserCodeError",
    "NumericalError",
]


class SbibError(Exception):
    """Base class of the project's own errors."""


class InputError(SbibError, ValueError):
    """Bad user input: a file, an option, a configuration field or an argument."""


class ParameterError(InputError):
    """A model parameter outside its admissible class (e.g. ``sigma < 1/2``)."""


class DataNotFoundError(InputError, FileNotFoundError):
    """A data file or directory the run needs is absent."""


class UserCodeError(InputError):
    """A user's code (a controller class) raised or misbehaved during a run: that run fails, an
    ensemble records it as failed and goes on (its other cases do not run that code)."""


class NumericalError(SbibError, RuntimeError):
    """The integration failed (NaN, blow-up, sub-stepping tolerance not met).

    Parameters
    ----------
    message : str
        What failed.
    time : float, optional
        Simulation time of the failure [s].
    state : dict, optional
        Names and values of the state that failed.
    hint : str, optional
        What the user can change to avoid it.
    """

    def __init__(self, message: str, time: float | None = None,
                 state: dict | None = None, hint: str | None = None) -> None:
        self.time = time
        self.state = dict(state or {})
        self.hint = hint
        parts = [message]
        if time is not None:
            parts.append(f"at t = {time:.6g} s")
        if self.state:
            parts.append("state: " + ", ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}"
                                               for k, v in self.state.items()))
        if hint:
            parts.append(f"hint: {hint}")
        super().__init__("; ".join(parts))
