"""Every public function, method and class of every package documents exactly its parameters.

The numpydoc sections are parsed by numpydoc's own parser (``numpydoc.docscrape``) and compared
with ``inspect.signature``; a parameter is documented when its name is an entry of Parameters or
Other Parameters (``a, b : float`` counts for both names), never because the name happens to occur
somewhere in the text. Checked, for each module of ``benchmark``, ``damper``, ``controllers`` and
``records`` found by ``pkgutil.walk_packages`` (``__main__`` modules skipped, they run on import):

- the module has a docstring;
- the public names: those in the module's ``__all__`` if it has one, else those not starting with
  ``_`` and defined in that module; functions (numba dispatchers through ``py_func``), classes,
  and the public methods (plain, static, class) defined in a public class;
- a public callable has a docstring (``inspect.getdoc``: a method overriding a documented one
  inherits its docstring, and then its parameters must match that docstring);
- every parameter of the signature, except ``self``/``cls``, is documented; ``*args``/``**kwargs``
  are documented as such or by the names they forward (extra documented names are then allowed);
- no documented parameter is missing from the signature (stale documentation);
- for a class, the constructor's parameters may be documented under Parameters or Attributes of
  the class docstring, or under Parameters of ``__init__``'s own docstring; classes whose
  constructor is not the project's (exceptions without ``__init__``, enums, protocols) are checked
  for a docstring only.

All failures are reported at once, one line each, as ``module.qualname: what``.
"""

from __future__ import annotations

import enum
import importlib
import inspect
import pkgutil
import re
import sys
import warnings
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from numpydoc.docscrape import NumpyDocString

PACKAGES = ("benchmark", "damper", "controllers", "records")

# Explicit exemptions, "module.qualname" -> why. Keep this tiny: document instead where possible.
ALLOWED: dict[str, str] = {}


def _is_project(obj: Any) -> bool:
    module = getattr(obj, "__module__", None) or ""
    return module.split(".")[0] in PACKAGES


def _function(obj: Any) -> Callable[..., Any] | None:
    """The plain Python function behind ``obj`` (a numba dispatcher's ``py_func``), or None."""
    if inspect.isfunction(obj):
        return obj
    py_func = getattr(obj, "py_func", None)
    if inspect.isfunction(py_func):
        return py_func
    return None


def project_modules(packages: tuple[str, ...] = PACKAGES) -> list[str]:
    """Names of every module of ``packages``, ``__main__`` modules excluded."""
    names = []
    for package_name in packages:
        package = importlib.import_module(package_name)
        names.append(package_name)
        for info in pkgutil.walk_packages(package.__path__, prefix=package_name + "."):
            if info.name.rsplit(".", 1)[-1] == "__main__":
                continue
            names.append(info.name)
    return sorted(names)


def public_objects(module: Any) -> Iterator[Any]:
    """The public functions and classes of ``module``, and the public methods of those classes."""
    if hasattr(module, "__all__"):
        candidates = [getattr(module, name) for name in module.__all__]
    else:
        candidates = [value for name, value in vars(module).items()
                      if not name.startswith("_") and getattr(value, "__module__", None) == module.__name__]
    for obj in candidates:
        if not _is_project(obj):
            continue  # re-exported third-party names and module-level constants
        if inspect.isclass(obj):
            yield obj
            for name, member in vars(obj).items():
                if name.startswith("_"):
                    continue
                if isinstance(member, (staticmethod, classmethod)):
                    member = member.__func__
                if _function(member) is not None:
                    yield member
        elif _function(obj) is not None:
            yield obj


def _documented(section: list[Any]) -> list[str]:
    """The names of a parsed numpydoc section's entries, ``a, b`` split into both names."""
    names: list[str] = []
    for entry in section:
        names.extend(part.strip() for part in entry.name.split(",") if part.strip())
    return names


def _parse(doc: str, label: str, problems: list[str]) -> NumpyDocString | None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpydoc warns on unknown sections: report them too
        try:
            return NumpyDocString(doc)
        except Exception as exc:  # numpydoc raises ParseError/ValueError/UserWarning subclasses
            problems.append(f"{label}: docstring does not parse as numpydoc ({str(exc).splitlines()[0]})")
            return None


def _constructor_is_projects(cls: type) -> bool:
    if issubclass(cls, enum.Enum) or getattr(cls, "_is_protocol", False):
        return False
    for klass in cls.__mro__:
        if "__init__" in vars(klass) or "__new__" in vars(klass):
            return _is_project(klass) or klass.__module__ == cls.__module__
    return False


def _compare(parameters: list[inspect.Parameter], documented: list[str], allowed_extra: list[str],
             label: str) -> list[str]:
    """Compare a signature's parameters with the documented names (``allowed_extra``: not stale)."""
    problems = []
    bare = [name.lstrip("*") for name in documented]
    names = {p.name for p in parameters}
    var = [p for p in parameters if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    extra = [name for name in bare if name not in names]
    for p in parameters:
        if p.name in ("self", "cls"):
            continue
        if p.name in bare:
            continue
        if p in var and extra:
            continue  # documented by the names it forwards
        star = "*" if p.kind == p.VAR_POSITIONAL else "**" if p.kind == p.VAR_KEYWORD else ""
        problems.append(f"{label}: parameter {star}{p.name!r} not documented")
    if not var:
        for name in extra:
            if name not in allowed_extra:
                problems.append(f"{label}: documents {name!r}, which is not a parameter")
    return problems


def _docstring(target: Any) -> str | None:
    """``inspect.getdoc``, which also inherits the docstring of an overridden class or static method."""
    doc = inspect.getdoc(target)
    if doc or not inspect.isfunction(target) or "." not in target.__qualname__:
        return doc
    owner: Any = sys.modules.get(target.__module__)
    for part in target.__qualname__.split(".")[:-1]:
        owner = getattr(owner, part, None)
    if not inspect.isclass(owner):
        return doc
    for base in owner.__mro__[1:]:
        member = vars(base).get(target.__name__)
        member = getattr(member, "__func__", member)
        inherited = getattr(member, "__doc__", None)
        if isinstance(inherited, str) and inherited.strip():
            return inspect.cleandoc(inherited)
    return doc


def docstring_problems(obj: Any) -> list[str]:
    """What is wrong with the docstring of a function, numba kernel, method or class, one line each."""
    label = f"{obj.__module__}.{getattr(obj, '__qualname__', getattr(obj, '__name__', '?'))}"
    target = _function(obj) or obj
    doc = _docstring(target)
    if not doc or not doc.strip():
        return [f"{label}: no docstring"]
    problems: list[str] = []
    parsed = _parse(doc, label, problems)
    if parsed is None:
        return problems
    documented = _documented(parsed["Parameters"]) + _documented(parsed["Other Parameters"])
    if inspect.isclass(obj):
        if not _constructor_is_projects(obj):
            return problems
        init = vars(obj).get("__init__")
        own = inspect.getdoc(init) if init is not None and init.__doc__ else None
        if own:
            init_doc = _parse(own, label + ".__init__", problems)
            if init_doc is not None:
                documented += _documented(init_doc["Parameters"]) + _documented(init_doc["Other Parameters"])
        try:
            signature = inspect.signature(obj)
        except (TypeError, ValueError):
            return problems
        attributes = _documented(parsed["Attributes"])  # document the constructor too, never stale
        return problems + _compare(list(signature.parameters.values()), documented + attributes,
                                   attributes, label)
    signature = inspect.signature(target)
    return problems + _compare(list(signature.parameters.values()), documented, [], label)


def all_problems(packages: tuple[str, ...] = PACKAGES) -> list[str]:
    """Every docstring problem of ``packages``, allow-listed ones left out."""
    problems: list[str] = []
    seen: set[int] = set()
    for name in project_modules(packages):
        module = importlib.import_module(name)
        if not (module.__doc__ or "").strip():
            problems.append(f"{name}: module has no docstring")
        for obj in public_objects(module):
            if id(obj) in seen or obj.__module__.split(".")[0] not in packages:
                continue  # re-exported by a façade: checked once, with its own package
            seen.add(id(obj))
            problems.extend(docstring_problems(obj))
    return [p for p in problems if p.split(":", 1)[0] not in ALLOWED]


@pytest.mark.parametrize("package", PACKAGES)
def test_every_public_docstring_documents_exactly_its_parameters(package):
    problems = all_problems((package,))
    assert not problems, f"{len(problems)} docstring problems:\n" + "\n".join(problems)


def test_packages_are_all_walked():
    modules = project_modules()
    for package in PACKAGES:
        assert sum(name.startswith(package + ".") for name in modules) >= 3, package
    assert not any(name.endswith("__main__") for name in modules)


_XREF = re.compile(r":(?:func|class|data|mod|meth|attr|exc):`~?((?:%s)\.[\w.]+)`" % "|".join(PACKAGES))


def resolves(target: str) -> bool:
    """Whether a dotted cross-reference names a module, or an attribute or dataclass field inside one."""
    parts = target.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for part in parts[i:]:
            if hasattr(obj, part):
                obj = getattr(obj, part)
            elif part in getattr(obj, "__dataclass_fields__", {}) or part in getattr(obj, "__annotations__", {}):
                return part == parts[-1]  # a field without a class-level default: nothing further to look up
            else:
                return False
        return True
    return False


def test_cross_references_in_docstrings_resolve():
    """``:func:`damper.x.y``` and the like name something that exists (modules move: #23)."""
    problems = []
    for name in project_modules():
        source = inspect.getsource(importlib.import_module(name))
        for target in sorted(set(_XREF.findall(source))):
            if not resolves(target):
                problems.append(f"{name}: cross-reference {target!r} does not resolve")
    assert not problems, "\n".join(problems)


def test_cross_reference_check_can_fail():
    assert resolves("damper") and resolves("records.record.Record") and resolves("records.catalogue.CatalogueEntry.pgv_m_s")
    assert not resolves("damper.no_such_module.f") and not resolves("records.record.Record.no_such_method")


# --- the checker itself can fail ------------------------------------------------------------------

def _undocumented_and_stale(x: float, n: int, A: float = 1.0) -> float:
    """Scale x by n and A (the docstring mentions n and A in prose but not in Parameters).

    Parameters
    ----------
    x : float
        Value.
    A : float
        Factor.
    alpha : float
        Gone from the signature.

    Returns
    -------
    float
        n * A * x.
    """
    return n * A * x


def _documented_right(x: float, *args: float, n: int = 1, **kwargs: float) -> float:
    """Sum.

    Parameters
    ----------
    x, n : float
        Value and count.
    *args : float
        More values.
    scale : float
        Forwarded through ``**kwargs``.

    Returns
    -------
    float
        The sum.
    """
    return x + n + sum(args) + sum(kwargs.values())


class _Spring:
    """A linear spring.

    Parameters
    ----------
    stiffness : float
        Stiffness k [N/m].
    damping : float
        Stale: not a constructor parameter.

    Attributes
    ----------
    stiffness : float
        Stiffness k [N/m].
    """

    def __init__(self, stiffness: float, length: float) -> None:
        self.stiffness = stiffness
        self.length = length

    def force(self, u: float) -> float:
        """Force."""
        return -self.stiffness * u


def test_checker_finds_undocumented_and_stale_parameters():
    problems = docstring_problems(_undocumented_and_stale)
    assert any("parameter 'n' not documented" in p for p in problems), problems
    assert any("documents 'alpha', which is not a parameter" in p for p in problems), problems
    assert not any("'x'" in p or "'A'" in p for p in problems), problems
    assert len(problems) == 2
    assert all(p.startswith(f"{__name__}._undocumented_and_stale: ") for p in problems)


def test_checker_accepts_comma_lists_and_forwarded_kwargs():
    assert docstring_problems(_documented_right) == []


def test_checker_checks_constructors_and_methods():
    problems = docstring_problems(_Spring)
    assert any("parameter 'length' not documented" in p for p in problems), problems
    assert any("documents 'damping'" in p for p in problems), problems
    assert docstring_problems(_Spring.force) == [f"{__name__}._Spring.force: parameter 'u' not documented"]
    assert any("no docstring" in p for p in docstring_problems(lambda y: y))


@pytest.mark.parametrize("doc", ["Text.\n\nParameters\n----------\nx : float\n    A.\n\nParameters\n----------\n",
                                 "Text.\n\nArgs\n----\nx : float\n    A.\n"])
def test_checker_reports_unparseable_docstrings(doc):
    def f(x):
        return x
    f.__doc__ = doc
    problems = docstring_problems(f)
    assert problems and ("does not parse" in problems[0] or "not documented" in problems[0]), problems
