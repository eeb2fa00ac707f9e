"""Named, bounded in-memory caches, each an explicit object that can be listed and cleared.

Work that is pure in its inputs (a discretised plant per building and step, a superstructure
read from its file, an equivalent-linear bearing, a building's design model, an uncontrolled
reference run) is kept in a :class:`Cache` (or a :class:`ReferenceCache`-like object with the
same ``name``/``clear``/``__len__``), never in a bare module-level dict. Every cache registers
itself under its name, so :func:`caches` lists them and :func:`clear_caches` empties them all:
results never depend on what is cached (``tests/test_caches.py`` clears every cache between two
runs and gets the same arrays). docs/ARCHITECTURE.md ("Caches") says where each one lives.
"""

from __future__ import annotations

import weakref
from collections import OrderedDict
from typing import Any, Callable, Hashable, Protocol

__all__ = ["Cache", "CacheLike", "FunctionCache", "WeakKeyCache", "register_cache", "caches", "clear_caches"]


class CacheLike(Protocol):
    """What the registry needs of a cache: a name, its size and ``clear()``."""

    name: str

    def clear(self) -> None:
        """Forget every entry."""

    def __len__(self) -> int: ...


_REGISTRY: "weakref.WeakValueDictionary[str, Any]" = weakref.WeakValueDictionary()


def register_cache(cache: Any) -> Any:
    """File ``cache`` (with ``name``, ``clear()`` and ``__len__``) under its name; returns it.

    A name already held by another live cache gets a numeric suffix (two worker caches of one
    kind may coexist); entries are held weakly, so a cache dies with its owner.

    Parameters
    ----------
    cache : object
        The cache.

    Returns
    -------
    object
        ``cache`` itself.
    """
    name = cache.name
    k = 2
    while name in _REGISTRY and _REGISTRY[name] is not cache:
        name = f"{cache.name}#{k}"
        k += 1
    _REGISTRY[name] = cache
    return cache


def caches() -> dict[str, Any]:
    """Every live registered cache by name (a snapshot)."""
    return dict(_REGISTRY.items())


def clear_caches() -> None:
    """Empty every registered cache (the next runs recompute; results are unchanged)."""
    for cache in list(_REGISTRY.values()):
        cache.clear()


class Cache:
    """A named least-recently-used cache of at most ``size`` entries.

    Parameters
    ----------
    name : str
        What it holds (shown by :func:`caches`).
    size : int
        Largest number of entries; the least recently used one goes first.
    """

    def __init__(self, name: str, size: int) -> None:
        if int(size) < 1:
            raise ValueError(f"Cache {name!r}: size {size!r}; expected >= 1")
        self.name = str(name)
        self.size = int(size)
        self._entries: OrderedDict[Hashable, Any] = OrderedDict()
        register_cache(self)

    def get(self, key: Hashable, default: Any = None) -> Any:
        """The value under ``key`` (marked recently used), else ``default``.

        Parameters
        ----------
        key : hashable
            The entry's key.
        default : object, optional
            Returned on a miss.
        """
        try:
            self._entries.move_to_end(key)
        except KeyError:
            return default
        return self._entries[key]

    def put(self, key: Hashable, value: Any) -> Any:
        """Store ``value`` under ``key`` (dropping the oldest entries beyond ``size``); returns it.

        Parameters
        ----------
        key : hashable
            The entry's key.
        value : object
            What to store.
        """
        self._entries[key] = value
        self._entries.move_to_end(key)
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)
        return value

    def get_or_compute(self, key: Hashable, compute: Callable[[], Any]) -> Any:
        """The value under ``key``, computed by ``compute()`` and stored on a miss.

        Parameters
        ----------
        key : hashable
            The entry's key.
        compute : callable
            Called without arguments on a miss.
        """
        sentinel = _MISSING
        value = self.get(key, sentinel)
        return self.put(key, compute()) if value is sentinel else value

    def clear(self) -> None:
        """Forget every entry."""
        self._entries.clear()

    def __len__(self) -> int:
        return len(self._entries)

    def __contains__(self, key: Hashable) -> bool:
        return key in self._entries

    def __repr__(self) -> str:
        return f"Cache({self.name!r}, {len(self)}/{self.size})"


class FunctionCache:
    """A ``functools.lru_cache``-wrapped function under a name, so that it can be listed and
    cleared like a :class:`Cache` (``len`` is its current size).

    Parameters
    ----------
    name : str
        What it holds.
    function : callable
        The ``lru_cache``-wrapped function.
    """

    def __init__(self, name: str, function: Any) -> None:
        self.name = str(name)
        self.function = function
        register_cache(self)

    def clear(self) -> None:
        """Forget every memoised call."""
        self.function.cache_clear()

    def __len__(self) -> int:
        return int(self.function.cache_info().currsize)

    def __repr__(self) -> str:
        return f"FunctionCache({self.name!r}, {len(self)})"


class WeakKeyCache:
    """A named cache keyed weakly by objects: an entry lives as long as its key object (e.g. one
    design model per building, gone with the building).

    Parameters
    ----------
    name : str
        What it holds.
    """

    def __init__(self, name: str) -> None:
        self.name = str(name)
        self._entries: "weakref.WeakKeyDictionary[Any, Any]" = weakref.WeakKeyDictionary()
        register_cache(self)

    def get(self, key: Any, default: Any = None) -> Any:
        """The value under ``key``, else ``default``.

        Parameters
        ----------
        key : object
            A weakly referenceable key.
        default : object, optional
            Returned on a miss.
        """
        return self._entries.get(key, default)

    def put(self, key: Any, value: Any) -> Any:
        """Store ``value`` under ``key`` (held while ``key`` lives); returns it.

        Parameters
        ----------
        key : object
            A weakly referenceable key.
        value : object
            What to store.
        """
        self._entries[key] = value
        return value

    def clear(self) -> None:
        """Forget every entry."""
        self._entries.clear()

    def __len__(self) -> int:
        return len(self._entries)

    def __repr__(self) -> str:
        return f"WeakKeyCache({self.name!r}, {len(self)})"


_MISSING = object()
