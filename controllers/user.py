"""A user's own controller: ``package.module:Class`` or ``path/to/file.py:Class``.

The class follows the controller interface of :mod:`controllers.base`: it is built with no
arguments, ``reset(context)`` (optional) is called once before a run with the
:class:`~controllers.base.ControlContext` (number of devices, control step, ``voltage_max``,
the measurement layout, the building's design model), and ``step(measurements) -> voltages``
at every control step with the measurement vector (layout: :mod:`controllers.measurements`;
SI units) and returns one command per device in ``[0, voltage_max]`` (the device model's input
range: volts, or amperes for a model fitted on coil currents). Subclassing
:class:`controllers.base.Controller` gives ``self.context`` and the slices.

:func:`load_user_controller` refuses, in one :class:`~benchmark.foundation.errors.InputError`
line naming the class, a spec that cannot be imported, a class that is not there, one that
cannot be built with no arguments, or whose ``step``/``reset`` take other arguments. During the
run (:class:`GuardedController`) an exception inside ``reset`` or ``step``, or commands outside
``[0, voltage_max]`` (beyond a rounding tolerance), end the run with one line naming the class,
the time and the offending device; a wrong number of commands or a non-finite one is reported
by :func:`controllers.base.check_voltages` with the same name. What the user's code prints goes
to standard error (sbib's standard output carries its tables and ``--json`` documents), and
:func:`user_controller_file` names the file that results and ensemble journals hash.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import importlib.util
import inspect
import sys
from pathlib import Path
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError, SbibError, UserCodeError
from controllers.base import CompiledController, ControlContext, Controller

__all__ = ["is_user_controller_spec", "load_user_controller", "user_controller_file", "GuardedController",
           "VOLTAGE_TOLERANCE"]

#: Commands may exceed ``[0, voltage_max]`` by this much (relative to ``voltage_max``) for rounding.
VOLTAGE_TOLERANCE = 1e-9


def is_user_controller_spec(spec: Any) -> bool:
    """``spec`` has the form ``module:Class`` or ``file.py:Class``.

    Parameters
    ----------
    spec : Any
        A ``--controller`` value; only a string with a ``:`` that does not start with it counts
        (registered names have no colon).
    """
    return isinstance(spec, str) and ":" in spec.strip() and not spec.strip().startswith(":")


def user_controller_file(spec: str) -> Path | None:
    """The Python file a user's controller is read from, or ``None`` (not a user's spec, or a
    module without a file).

    Results and ensemble journals hash this file: an edited controller is another controller,
    whether it is named by its file (``path/to/file.py:Class``) or by its module
    (``package.module:Class``, located by Python's import system; its parent package is imported).

    Parameters
    ----------
    spec : str
        A ``--controller`` value.
    """
    if not is_user_controller_spec(spec):
        return None
    target = spec.strip().rpartition(":")[0]
    if _is_file_target(target):
        path = Path(target).expanduser()
        return path.resolve() if path.is_file() else None
    module = sys.modules.get(target)
    origin = getattr(module, "__file__", None) if module is not None else None
    if origin is None:
        try:
            found = importlib.util.find_spec(target)
        except (ImportError, ValueError):
            return None
        origin = found.origin if found is not None else None
    path = Path(origin) if origin else None
    return path.resolve() if path is not None and path.is_file() else None


def _is_file_target(target: str) -> bool:
    return target.endswith(".py") or "/" in target or "\\" in target


def _split(spec: str) -> tuple[str, str]:
    target, _, cls_name = spec.strip().rpartition(":")
    if not target or not cls_name.isidentifier():
        raise InputError(f"controller {spec!r}: expected package.module:Class or path/to/file.py:Class")
    return target, cls_name


def _import(spec: str, target: str):
    if _is_file_target(target):
        path = Path(target)
        if not path.is_file():
            raise InputError(f"controller {spec!r}: file {target} not found")
        digest = hashlib.sha1(str(path.resolve()).encode()).hexdigest()[:12]
        name = f"sbib_user_controller_{path.stem}_{digest}"
        if name in sys.modules:
            return sys.modules[name]
        module_spec = importlib.util.spec_from_file_location(name, path)
        if module_spec is None or module_spec.loader is None:
            raise InputError(f"controller {spec!r}: {target} cannot be loaded as a Python file")
        module = importlib.util.module_from_spec(module_spec)
        sys.modules[name] = module
        try:
            with _user_output():
                module_spec.loader.exec_module(module)
        except SbibError:
            sys.modules.pop(name, None)
            raise
        except Exception as exc:  # the user's module failed to import: say which and why, in one line
            sys.modules.pop(name, None)
            raise InputError(f"controller {spec!r}: importing {target} failed: {type(exc).__name__}: "
                             f"{_one_line(exc)}") from None
        return module
    try:
        with _user_output():
            return importlib.import_module(target)
    except ModuleNotFoundError as exc:
        hint = ("; a package of the current directory: run with PYTHONPATH=. or give path/to/file.py:Class"
                if Path(target.split(".")[0]).is_dir() or Path(target.split(".")[0] + ".py").is_file() else "")
        raise InputError(f"controller {spec!r}: module {target!r} not found ({_one_line(exc)}){hint}") from None
    except Exception as exc:
        raise InputError(f"controller {spec!r}: importing {target} failed: {type(exc).__name__}: "
                         f"{_one_line(exc)}") from None


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text[:300] if text else "(no message)"


def _takes_one_argument(function, bound: bool) -> bool:
    try:
        sig = inspect.signature(function)
    except (TypeError, ValueError):
        return True  # builtins: cannot tell, the run will say
    try:
        sig.bind(*([object()] if bound else [object(), object()]))
    except TypeError:
        return False
    return True


def _method_takes_one_argument(cls, name: str) -> bool:
    # a staticmethod or classmethod is called without self: step(measurements) binds one argument
    bound = isinstance(inspect.getattr_static(cls, name, None), (staticmethod, classmethod))
    return _takes_one_argument(getattr(cls, name), bound=bound)


def _user_output():
    """Where the user's code prints: standard error, so that what sbib writes to standard output
    (a ``--json`` document, a table) stays sbib's alone."""
    return contextlib.redirect_stdout(sys.stderr)


def load_user_controller(spec: str) -> "GuardedController":
    """Import the class ``spec`` names, check its signature, build it and wrap it in a guard.

    Parameters
    ----------
    spec : str
        ``package.module:Class`` (imported) or ``path/to/file.py:Class`` (loaded from the file).

    Returns
    -------
    GuardedController
        The user's instance, built with no arguments, behind the run-time checks.

    Raises
    ------
    InputError
        The module or file cannot be imported, the class is missing, is not a class, cannot be
        built with no arguments, or its ``step``/``reset`` do not take one argument.
    """
    target, cls_name = _split(spec)
    module = _import(spec, target)
    cls = getattr(module, cls_name, None)
    if cls is None:
        raise InputError(f"controller {spec!r}: {target} has no {cls_name}")
    if not inspect.isclass(cls):
        raise InputError(f"controller {spec!r}: {cls_name} is not a class (a {type(cls).__name__!r} object); expected a class")
    step = getattr(cls, "step", None)
    if not callable(step):
        raise InputError(f"controller {spec!r}: {cls_name} has no step(self, measurements) method")
    if not _method_takes_one_argument(cls, "step"):
        raise InputError(f"controller {spec!r}: {cls_name}.step{inspect.signature(step)} must take one "
                         "argument, the measurement vector: step(self, measurements)")
    reset = getattr(cls, "reset", None)
    if reset is not None and not _method_takes_one_argument(cls, "reset"):
        raise InputError(f"controller {spec!r}: {cls_name}.reset{inspect.signature(reset)} must take one "
                         "argument, the context: reset(self, context)")
    try:
        inspect.signature(cls).bind()
    except TypeError:
        raise InputError(f"controller {spec!r}: {cls_name}{inspect.signature(cls)} cannot be built with no "
                         "arguments; give its parameters defaults") from None
    except ValueError:
        pass
    try:
        with _user_output():
            instance = cls()
    except SbibError:
        raise
    except Exception as exc:
        raise InputError(f"controller {spec!r}: {cls_name}() raised {type(exc).__name__}: {_one_line(exc)}") from None
    return GuardedController(instance, spec)


class GuardedController(Controller):
    """A user's controller behind the checks of the module docstring (same ``step``/``reset``).

    Runs from Python at every control step (``compiled()`` is the user's, usually ``None``).

    Parameters
    ----------
    inner : Any
        The user's controller instance (``step(measurements)``, optional ``reset(context)``,
        ``compiled()`` and ``describe()``).
    spec : str
        The spec it was loaded from; names it in errors and results and rebuilds it in a
        worker process.
    """

    def __init__(self, inner: Any, spec: str) -> None:
        super().__init__()
        self.inner = inner
        self.spec = spec
        self.name = spec
        self._k = 0

    def __reduce__(self):  # rebuilt from its spec in a worker process (the class may be a file's)
        return (load_user_controller, (self.spec,))

    def __deepcopy__(self, memo):
        return load_user_controller(self.spec)

    def _fail(self, where: str, exc: BaseException) -> InputError:
        t = self._k * self.context.control_step if self.context is not None else 0.0
        return UserCodeError(f"controller {self.spec!r}: {where} raised {type(exc).__name__} at t = {t:.6g} s: "
                          f"{_one_line(exc)}")

    def reset(self, context: ControlContext) -> None:
        super().reset(context)
        self._k = 0
        reset = getattr(self.inner, "reset", None)
        if reset is not None:
            try:
                with _user_output():
                    reset(context)
            except SbibError:
                raise
            except (Exception, SystemExit) as exc:  # sys.exit() in user code ends the run, not sbib
                raise self._fail("reset(context)", exc) from None

    def compiled(self) -> CompiledController | None:
        compiled = getattr(self.inner, "compiled", None)
        if not callable(compiled):
            return None
        try:
            with _user_output():
                out = compiled()
        except SbibError:
            raise
        except (Exception, SystemExit) as exc:
            raise self._fail("compiled()", exc) from None
        if out is not None and not isinstance(out, CompiledController):
            raise UserCodeError(f"controller {self.spec!r}: compiled() returned {type(out).__name__}; expected "
                                "None or a controllers.base.CompiledController")
        return out

    def step(self, measurements: np.ndarray) -> np.ndarray:
        assert self.context is not None
        try:
            with _user_output():
                raw = self.inner.step(measurements)
        except SbibError:
            raise
        except (Exception, SystemExit) as exc:
            raise self._fail("step(measurements)", exc) from None
        t = self._k * self.context.control_step
        self._k += 1
        if raw is None:
            raise UserCodeError(f"controller {self.spec!r}: step(measurements) returned None at t = {t:.6g} s; "
                                f"expected {self.context.voltage_max.size} commands (a missing return?)")
        if np.iscomplexobj(raw):
            # numpy would drop the imaginary part with a ComplexWarning
            raise UserCodeError(f"controller {self.spec!r}: step(measurements) returned complex commands at "
                                f"t = {t:.6g} s; expected real numbers")
        try:
            v = np.asarray(raw, dtype=np.float64)
        except (TypeError, ValueError):
            return raw  # check_voltages names the type
        vmax = self.context.voltage_max
        if v.shape == vmax.shape:
            tol = VOLTAGE_TOLERANCE * np.maximum(vmax, 1.0)
            bad = np.flatnonzero(np.isfinite(v) & ((v < -tol) | (v > vmax + tol)))
            if bad.size:
                j = int(bad[0])
                raise UserCodeError(f"controller {self.spec!r}: command {v[j]:.10g} for device {j} at t = {t:.6g} s is "
                                 f"outside [0, {vmax[j]:.10g}] (the device's input range, in its model's unit: V or A)"
                                 + (f"; {bad.size} devices" if bad.size > 1 else ""))
        return v

    def describe(self) -> dict:
        out = {"name": self.spec, "class": type(self.inner).__name__}
        describe = getattr(self.inner, "describe", None)
        if callable(describe):
            try:
                with _user_output():
                    out["parameters"] = describe()
            except Exception:  # a description is optional; a broken one must not stop the run
                pass
        return out
