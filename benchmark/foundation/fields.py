"""Field names of the project's JSON inputs: a misspelt field is refused, not ignored.

A user's structure variant or isolation layer is a JSON object whose optional fields have
defaults; a field written ``"paramters"`` or ``"n_floor"`` would otherwise be skipped and the
default used without a word. :func:`check_field_names` refuses, in one line, every field that is
not read but lies close to one that is (:func:`difflib.get_close_matches`), and, where the
object holds no free-form fields (``strict``), every field that is not read.
"""

from __future__ import annotations

import difflib
from typing import Iterable

from benchmark.foundation.errors import InputError

__all__ = ["check_field_names", "NOTE_FIELDS", "CLOSE_MATCH"]

#: Free-form fields every object may carry (comments for people, never read).
NOTE_FIELDS = ("comment", "comments", "note", "notes", "description", "source", "units")
#: Similarity (difflib's ratio) above which an unread field is taken for a misspelling.
CLOSE_MATCH = 0.75


def check_field_names(data: dict, known: Iterable[str], where: str, strict: bool = False) -> None:
    """Refuse a field of ``data`` that is not in ``known`` and looks like a misspelling of one
    (or, with ``strict``, any field not in ``known`` or :data:`NOTE_FIELDS`).

    Parameters
    ----------
    data : dict
        The JSON object as read.
    known : iterable of str
        The fields the reader uses or accepts.
    where : str
        The object's place, for the message (a file, ``file: groups[2]``).
    strict : bool
        Also refuse fields that resemble no known one.

    Raises
    ------
    InputError
        One line naming the field and the one it resembles, or the fields accepted.
    """
    names = sorted(set(known))
    for key in data:
        if key in names or key in NOTE_FIELDS or not isinstance(key, str):
            continue
        match = difflib.get_close_matches(key, names, n=1, cutoff=CLOSE_MATCH)
        if match:
            raise InputError(f"{where}: field '{key}' is not one sbib reads; did you mean '{match[0]}'?")
        if strict:
            raise InputError(f"{where}: field '{key}' is not one sbib reads; expected {', '.join(names)} "
                             f"(and free-form {', '.join(NOTE_FIELDS)})")
