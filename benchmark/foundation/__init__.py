"""The foundation layer: utilities every package of the project may import.

:mod:`~benchmark.foundation.errors` (the error hierarchy and its exit codes),
:mod:`~benchmark.foundation.atomic` (writes that never leave half a file),
:mod:`~benchmark.foundation.paths` (where the shared data live),
:mod:`~benchmark.foundation.provenance` (what produced a result),
:mod:`~benchmark.foundation.figures` (saving matplotlib figures as files) and
:mod:`~benchmark.foundation.kernel_cache` (numba's on-disk cache).

This subpackage imports nothing else from the project (the contract in ``pyproject.toml``,
checked by import-linter in ``make test``); see ``docs/ARCHITECTURE.md``.
"""
