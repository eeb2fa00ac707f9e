"""Lazy package façades (PEP 562): ``import benchmark as sb; sb.simulate(...)`` without deep imports.

A package ``__init__`` declares which public name lives in which module and hands the table to
:func:`lazy_exports`; the module is imported on first access of one of its names, so importing the
package stays cheap (``records`` and ``damper`` import :mod:`benchmark.foundation` without loading
the simulator) and a module can move without breaking users' code, as python-control's
``import control as ct; ct.ss(...)`` does. The import goes through :func:`importlib.import_module`
on a name from the table: a façade is the one sanctioned place where a package names a module
above it (``tests/test_architecture.py`` checks that every table entry resolves).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, table: Mapping[str, str],
                 namespace: dict[str, Any]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """Module-level ``__getattr__`` and ``__dir__`` of a package that re-exports lazily.

    Parameters
    ----------
    package : str
        The package's name (``__name__`` of its ``__init__``), used in error messages.
    table : mapping of str to str
        Public name -> the module that defines it (``"simulate": "benchmark.simulator.simulation"``).
    namespace : dict
        The package's ``globals()``: a name, once loaded, is stored there so that later accesses
        skip ``__getattr__``.

    Returns
    -------
    (getattr, dir) : tuple of callables
        To be bound as the package's ``__getattr__`` and ``__dir__``.
    """

    def __getattr__(name: str) -> Any:
        module = table.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(table))

    return __getattr__, __dir__
