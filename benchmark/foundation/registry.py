"""One registration pattern: a name -> class table filled by a class decorator.

Damper models (:data:`damper.models.base.MODELS`) and controllers
(:data:`controllers.base.CONTROLLERS`) are each a :class:`Registry`; a new one is *one decorated
class*::

    @register_model
    @dataclass(frozen=True)
    class MyDamper(DamperModel):
        name: ClassVar[str] = "my-damper"
        ...

The decorator checks the class against the family's contract (its base class, a name, extra
checks of the family) and refuses a name already taken by another class, so nothing is chosen
by hand in a second place.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar

from benchmark.foundation.errors import InputError

__all__ = ["Registry"]

T = TypeVar("T", bound=type)


class Registry(dict):
    """A ``{name: class}`` table of one family, filled by :meth:`register` (a class decorator).

    Parameters
    ----------
    kind : str
        What the family is called in messages (``"damper model"``).
    base : type, optional
        The class every member must subclass (the family's contract).
    check : callable, optional
        ``check(cls) -> str | None``: a further check of the family; a returned text is the
        reason the class is refused.
    """

    def __init__(self, kind: str, base: type | None = None,
                 check: Callable[[type], str | None] | None = None) -> None:
        super().__init__()
        self.kind = kind
        self.base = base
        self.check = check

    def register(self, cls: T) -> T:
        """Register ``cls`` under its ``name`` attribute and return it (use as a decorator).

        Parameters
        ----------
        cls : type
            The class; its ``name`` (a non-empty str) is the key.

        Returns
        -------
        type
            ``cls`` itself.

        Raises
        ------
        InputError
            If ``cls`` is not a class of the family, has no name, fails the family's check, or
            its name is taken by another class.
        """
        where = f"register {self.kind}"
        if not isinstance(cls, type) or (self.base is not None and not issubclass(cls, self.base)):
            base = f"{self.base.__module__}.{self.base.__qualname__}" if self.base else "a class"
            raise InputError(f"{where}: {cls!r} is not a subclass of {base}")
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name.strip():
            raise InputError(f"{where}: {cls.__name__} has no name (a class attribute 'name')")
        if self.check is not None:
            problem = self.check(cls)
            if problem:
                raise InputError(f"{where}: {cls.__name__}: {problem}")
        taken = self.get(name)
        reloaded = taken is not None and (taken.__module__, taken.__qualname__) == (cls.__module__, cls.__qualname__)
        if taken is not None and taken is not cls and not reloaded:
            raise InputError(f"{where}: {cls.__name__}: the name {name!r} is already registered by "
                             f"{taken.__module__}.{taken.__qualname__}")
        self[name] = cls
        return cls

    def unregister(self, name: str) -> None:
        """Remove ``name`` (tests that register a class of their own clean up with it).

        Parameters
        ----------
        name : str
            A registered name (an unknown one is ignored).
        """
        self.pop(name, None)

    def get_class(self, name: str) -> Any:
        """The class registered as ``name``.

        Parameters
        ----------
        name : str
            A registered name.

        Returns
        -------
        type
            The class.

        Raises
        ------
        InputError
            For an unknown name (the message lists the known ones).
        """
        try:
            return self[name]
        except (KeyError, TypeError):
            raise InputError(f"{self.kind}: unknown name {name!r}; expected one of "
                             + ", ".join(sorted(self))) from None
