"""Controller names → controller factories (the names the CLI and the study use)."""

from __future__ import annotations

from typing import Any, Callable

from benchmark.foundation.errors import InputError
from controllers.passive import PassiveOff
from controllers.passive import PassiveOn
from controllers.clipped_optimal import ClippedOptimal
from controllers.modulated import ModulatedClippedOptimal
from controllers.skyhook import Skyhook
from controllers.lyapunov import Lyapunov
from controllers.user import is_user_controller_spec, load_user_controller

__all__ = ["CONTROLLERS", "controller_names", "get_controller"]


def _passive_off():
    return PassiveOff()


def _passive_on():
    return PassiveOn()


def _clipped_optimal():
    return ClippedOptimal()


def _modulated():
    return ModulatedClippedOptimal()


def _skyhook():
    return Skyhook()


def _lyapunov():
    return Lyapunov()


#: Built-in controllers by name; ``none`` is the uncontrolled building (no devices).
CONTROLLERS: dict[str, Callable[[], Any] | None] = {
    "none": None,
    "passive-off": _passive_off,
    "passive-on": _passive_on,
    "clipped-optimal": _clipped_optimal,
    "modulated": _modulated,
    "skyhook": _skyhook,
    "lyapunov": _lyapunov,
}


def controller_names() -> tuple[str, ...]:
    """Names accepted by :func:`get_controller`."""
    return tuple(CONTROLLERS)


def get_controller(name: str) -> Any:
    """A new controller for ``name`` (``None`` for ``"none"``: the run without devices).

    ``name`` may also be a user's class, ``package.module:Class`` or ``path/to/file.py:Class``
    (:func:`controllers.user.load_user_controller`: checked, and guarded during the run).

    Raises
    ------
    InputError
        For an unknown name (the message lists the known ones) or a bad user class.
    """
    if is_user_controller_spec(name):
        return load_user_controller(name)
    key = name.strip().lower()
    if key not in CONTROLLERS:
        raise InputError(f"controller {name!r} unknown; expected one of {', '.join(CONTROLLERS)}, "
                         "or a class of yours as package.module:Class or path/to/file.py:Class")
    factory = CONTROLLERS[key]
    return None if factory is None else factory()
