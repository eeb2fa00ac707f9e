"""Controller names -> controller classes (the names the CLI and the study use).

A controller is one class decorated with :func:`controllers.base.register_controller`; this module
imports the built-in ones (which registers them) and builds one by name.
"""

from __future__ import annotations

from typing import Any

from benchmark.foundation.errors import InputError
from controllers.base import CONTROLLERS, register_controller
# Importing the built-in controllers registers them (each is one class decorated with
# ``register_controller``).
from controllers import passive, clipped_optimal, modulated, skyhook, lyapunov  # noqa: F401,I001
from controllers.user import is_user_controller_spec, load_user_controller

__all__ = ["CONTROLLERS", "register_controller", "controller_names", "get_controller", "NO_CONTROLLER"]

#: The name of the uncontrolled building (no devices): not a controller, the reference of J1-J9.
NO_CONTROLLER = "none"


def controller_names() -> tuple[str, ...]:
    """Names accepted by :func:`get_controller`: ``"none"`` first, then the registered controllers.

    Returns
    -------
    tuple of str
        The names.
    """
    return (NO_CONTROLLER, *CONTROLLERS)


def get_controller(name: str) -> Any:
    """A new controller for ``name`` (``None`` for ``"none"``: the run without devices).

    ``name`` may also be a user's class, ``package.module:Class`` or ``path/to/file.py:Class``
    (:func:`controllers.user.load_user_controller`: checked, and guarded during the run).

    Parameters
    ----------
    name : str
        A registered name (:func:`controller_names`, case-insensitive) or a user's class.

    Returns
    -------
    Controller or None
        A new instance of the registered (or the user's) class.

    Raises
    ------
    InputError
        For an unknown name (the message lists the known ones) or a bad user class.
    """
    if is_user_controller_spec(name):
        return load_user_controller(name)
    key = name.strip().lower()
    if key == NO_CONTROLLER:
        return None
    if key not in CONTROLLERS:
        raise InputError(f"controller {name!r} unknown; expected one of {', '.join(controller_names())}, "
                         "or a class of yours as package.module:Class or path/to/file.py:Class")
    return CONTROLLERS[key]()
