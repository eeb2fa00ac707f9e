"""Read a text input file, or reject it in one line when it is not UTF-8 text.

Every reader of a user's text file (records, damper tests, isolation JSON, ensemble TOML,
the structure file) goes through :func:`read_text`, so that a binary file (an image, an HDF5
file, a spreadsheet) or a file in another encoding gives the project's usual one-line
:class:`~benchmark.foundation.errors.InputError` naming the file and where the problem is, not a
``UnicodeDecodeError`` traceback. The input files of the project are UTF-8 (ASCII is UTF-8);
a file saved in Latin-1 or Windows-1252 has to be converted (``iconv -f latin1 -t utf-8``).
A UTF-8 byte-order mark is accepted and dropped.
"""

from __future__ import annotations

import os
from pathlib import Path

from benchmark.foundation.errors import DataNotFoundError, InputError

__all__ = ["read_text", "decode_text", "parse_float"]

#: Leading bytes of the compressed archives a record or test may come in.
_ARCHIVES = ((b"PK\x03\x04", "zip archive"), (b"\x1f\x8b", "gzip-compressed file"),
             (b"7z\xbc\xaf\x27\x1c", "7z archive"))

#: Bytes looked at for NUL characters, which never occur in a text file.
_SNIFF = 8192


def decode_text(raw: bytes, where: str) -> str:
    """Decode ``raw`` as UTF-8 text, or raise a one-line :class:`InputError` naming ``where``.

    Parameters
    ----------
    raw : bytes
        The file's content.
    where : str
        The file (or other origin) to name in the message.

    Raises
    ------
    InputError
        A NUL byte (a binary file), or bytes that are not UTF-8 (the message gives the line
        and the offending byte).
    """
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):  # a UTF-16 byte-order mark (a spreadsheet's "Unicode text")
        raise InputError(f"{where}: UTF-16 text; expected UTF-8 (save it as UTF-8 or plain CSV)")
    for magic, kind in _ARCHIVES:
        if raw.startswith(magic):
            raise InputError(f"{where}: a {kind}; expected a text file (extract it first)")
    if b"\x00" in raw[:_SNIFF] or (len(raw) > _SNIFF and b"\x00" in raw):
        raise InputError(f"{where}: looks like a binary file (it holds NUL bytes); expected a UTF-8 text file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise InputError(f"{where}:{line}: byte 0x{raw[exc.start]:02x} is not UTF-8 text; expected a UTF-8 "
                         "text file (a binary file, or convert it: iconv -f latin1 -t utf-8)") from None
    return text[1:] if text.startswith("\ufeff") else text


def read_text(path: str | os.PathLike, what: str = "file") -> str:
    """Return the UTF-8 text of ``path``.

    Parameters
    ----------
    path : path-like
        The file.
    what : str
        What the file is, for the not-found message (``"record file"``, ...).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Not a regular file, a binary file or not UTF-8 (see :func:`decode_text`).
    """
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: {what} not found")
    if not path.is_file():
        raise InputError(f"{path}: not a regular file; expected a {what}")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    return decode_text(raw, str(path))


def parse_float(token: str) -> float:
    """A number written in a text file: what :func:`float` reads, and Fortran's ``D`` exponent.

    Fortran programs (and the files of older strong-motion and test-rig software) write
    ``1.0D-03`` for ``1.0E-03``. Every reader of numbers in a user's text file uses this, so
    that such a file reads alike whichever format carries it.

    Parameters
    ----------
    token : str
        One cell of the file.

    Raises
    ------
    ValueError
        Not a number (as :func:`float`); the readers turn it into their one-line message.
    """
    try:
        return float(token)
    except ValueError:
        if "d" not in token and "D" not in token:
            raise
        return float(token.replace("D", "E").replace("d", "e"))

