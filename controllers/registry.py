"""Controller names → controller factories (the names the CLI and the study use)."""

from __future__ import annotations

from typing import Any, Callable

from benchmark.foundation.errors import InputError

__all__ = ["CONTROLLERS", "controller_names", "get_controller"]


def _passive_off():
    from controllers.passive import PassiveOff
    return PassiveOff()


def _passive_on():
    from controllers.passive import PassiveOn
    return PassiveOn()


def _clipped_optimal():
    from controllers.clipped_optimal import ClippedOptimal
    return ClippedOptimal()


def _modulated():
    from controllers.modulated import ModulatedClippedOptimal
    return ModulatedClippedOptimal()


def _skyhook():
    from controllers.skyhook import Skyhook
    return Skyhook()


def _lyapunov():
    from controllers.lyapunov import Lyapunov
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

    Raises
    ------
    InputError
        For an unknown name (the message lists the known ones).
    """
    key = name.strip().lower()
    if key not in CONTROLLERS:
        raise InputError(f"controller {name!r} unknown; expected one of {', '.join(CONTROLLERS)}")
    factory = CONTROLLERS[key]
    return None if factory is None else factory()
