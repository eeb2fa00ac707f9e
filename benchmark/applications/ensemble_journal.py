"""Append-only, fsync'd journal of finished ensemble runs: the source of truth for resuming.

An ensemble (:mod:`benchmark.applications.ensemble`) writes one line per finished run to a journal beside
its HDF5 file (``<out>.journal``) and rebuilds the HDF5 file from the journal, atomically. A
run whose line reached the disk is never redone; a run that was in flight when the process
was interrupted (Ctrl-C, ``kill -9``, power loss) is redone.

Line format (UTF-8, one record per line)::

    <crc32 of the JSON text, 8 hex digits> <JSON text>\\n

The first line is a header (``{"sbib_ensemble_journal": 1, ...}``) that ties the journal to
the settings that decide every result (base seed, run function). A torn last line (no
newline, unparsable or with a wrong checksum: the process died while writing it) is ignored
and cut off before the next append; a damaged line anywhere else is an
:class:`~benchmark.foundation.errors.InputError` naming the file and line, since the file was then
altered by something other than an interrupted append.

Floats are written with ``repr`` (exact round trip); arrays as base-64 of their raw bytes with
dtype and shape, so results read back are bit-identical to those computed.
"""

from __future__ import annotations

import base64
import json
import os
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = ["JournalEntry", "Journal", "encode_result", "decode_result", "JOURNAL_VERSION"]

JOURNAL_VERSION = 1


@dataclass(frozen=True)
class JournalEntry:
    """One finished run.

    Parameters
    ----------
    key : str
        The case key (:attr:`benchmark.applications.ensemble.EnsembleMember.key`), unique within an ensemble.
    status : str
        ``"ok"`` or ``"failed"`` (a :class:`~benchmark.foundation.errors.NumericalError` in the run).
    result : dict
        Metric name → float or ``numpy.ndarray`` (empty when failed).
    error : str
        The error message of a failed run (empty when ok).
    elapsed_s : float
        Wall time of the run on its worker [s] (informative; not part of the result).
    """

    key: str
    status: str
    result: dict[str, Any] = field(default_factory=dict)
    error: str = ""
    elapsed_s: float = 0.0


def encode_result(result: dict[str, Any]) -> dict[str, Any]:
    """Encode a ``result`` dict (metric → number or array) for JSON so that decoding gives bit-identical values.

    Parameters
    ----------
    result : dict[str, Any]
        Metric name → number or array.
    """
    encoded: dict[str, Any] = {}
    for name, value in result.items():
        if isinstance(value, np.ndarray) and value.ndim > 0:
            arr = np.ascontiguousarray(value)
            encoded[name] = {"__ndarray__": base64.b64encode(arr.tobytes()).decode("ascii"),
                             "dtype": arr.dtype.str, "shape": list(arr.shape)}
        elif isinstance(value, (bool, np.bool_)):
            encoded[name] = bool(value)
        elif isinstance(value, (int, np.integer)):
            encoded[name] = int(value)
        else:
            encoded[name] = float(value)  # repr round-trips exactly; NaN/inf as JSON extensions
    return encoded


def decode_result(encoded: dict[str, Any]) -> dict[str, Any]:
    """Inverse of :func:`encode_result`: ``encoded`` (the JSON object of one run) → result dict.

    Parameters
    ----------
    encoded : dict[str, Any]
        The JSON object of one run (:func:`encode_result`).
    """
    result: dict[str, Any] = {}
    for name, value in encoded.items():
        if isinstance(value, dict) and "__ndarray__" in value:
            raw = base64.b64decode(value["__ndarray__"])
            result[name] = np.frombuffer(raw, dtype=np.dtype(value["dtype"])).reshape(value["shape"]).copy()
        else:
            result[name] = value
    return result


def _format_line(payload: dict[str, Any]) -> bytes:
    text = json.dumps(payload, separators=(",", ":"), sort_keys=True)
    return f"{zlib.crc32(text.encode('utf-8')):08x} {text}\n".encode("utf-8")


def _parse_line(line: bytes) -> dict[str, Any] | None:
    """Return the payload of a journal line, or None when it is damaged."""
    try:
        text = line.decode("utf-8")
        crc, _, body = text.partition(" ")
        if len(crc) != 8 or int(crc, 16) != zlib.crc32(body.encode("utf-8")):
            return None
        payload = json.loads(body)
    except (UnicodeDecodeError, ValueError):
        return None
    return payload if isinstance(payload, dict) else None


class Journal:
    """An append-only journal file of finished runs.

    Parameters
    ----------
    path : path-like
        Journal file; created with ``header`` if absent.
    header : dict
        Settings that decide every result (e.g. ``base_seed``, ``run``). When the file exists,
        its header must agree on every key given here, otherwise an :class:`InputError` says
        which setting differs (the old results would not belong to the new ensemble).

    Attributes
    ----------
    entries : dict[str, JournalEntry]
        Finished runs read from the file, by case key (later lines win).
    """

    def __init__(self, path: str | os.PathLike, header: dict[str, Any]) -> None:
        self.path = Path(path)
        self.header = {"sbib_ensemble_journal": JOURNAL_VERSION, **header}
        self.entries: dict[str, JournalEntry] = {}
        self.torn_line_ignored = False
        self._good_size = 0
        self._fh = None
        if self.path.exists() and self.path.stat().st_size > 0:
            self._load()
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)

    # -- reading -------------------------------------------------------------------------------
    def _load(self) -> None:
        data = self.path.read_bytes()
        lines = data.split(b"\n")
        # data ends with b"\n" when complete, so the last chunk is b""; otherwise it is torn.
        complete, tail = lines[:-1], lines[-1]
        offset = 0
        parsed: list[tuple[int, dict[str, Any], int]] = []
        for number, line in enumerate(complete, start=1):
            payload = _parse_line(line)
            end = offset + len(line) + 1
            if payload is None:
                if number == len(complete) and not tail:
                    self.torn_line_ignored = True  # damaged last line: the append that died
                    break
                raise InputError(f"{self.path}:{number}: damaged journal line (checksum or JSON); "
                                 "the journal was altered; delete it to start the ensemble afresh")
            parsed.append((number, payload, end))
            offset = end
        if tail:
            self.torn_line_ignored = True
        if not parsed:
            self._good_size = 0
            return
        number, head, _ = parsed[0]
        if head.get("sbib_ensemble_journal") != JOURNAL_VERSION:
            raise InputError(f"{self.path}:1: not an sbib ensemble journal (version "
                             f"{JOURNAL_VERSION} header expected)")
        for name, value in self.header.items():
            if head.get(name) != value:
                raise InputError(
                    f"{self.path}: journal was written with {name} = {head.get(name)!r}, the ensemble "
                    f"now has {name} = {value!r}; its finished runs do not belong to this ensemble "
                    "(delete the journal or write to another --out)")
        for number, payload, _ in parsed[1:]:
            try:
                entry = JournalEntry(key=str(payload["key"]), status=str(payload["status"]),
                                     result=decode_result(payload.get("result", {})),
                                     error=str(payload.get("error", "")),
                                     elapsed_s=float(payload.get("elapsed_s", 0.0)))
            except (KeyError, TypeError, ValueError) as exc:
                raise InputError(f"{self.path}:{number}: journal entry lacks a field ({exc})") from None
            self.entries[entry.key] = entry
        self._good_size = parsed[-1][2]

    # -- writing -------------------------------------------------------------------------------
    def open(self) -> "Journal":
        """Open for appending: cut off a torn last line, write the header if the file is new."""
        if self._fh is not None:
            return self
        exists = self.path.exists()
        fh = open(self.path, "r+b" if exists else "w+b")
        fh.truncate(self._good_size)
        fh.seek(self._good_size)
        self._fh = fh
        if self._good_size == 0:
            self._write(self.header)
            self._fsync_directory()
        return self

    def _write(self, payload: dict[str, Any]) -> None:
        assert self._fh is not None, "journal not open"
        self._fh.write(_format_line(payload))
        self._fh.flush()
        os.fsync(self._fh.fileno())

    def _fsync_directory(self) -> None:
        try:
            fd = os.open(self.path.parent, os.O_RDONLY)
        except OSError:
            return
        try:
            os.fsync(fd)
        except OSError:
            pass
        finally:
            os.close(fd)

    def append(self, entry: JournalEntry) -> None:
        """Write one finished run and fsync it; it will not be redone after an interruption.

        Parameters
        ----------
        entry : JournalEntry
            The finished run.
        """
        self.open()
        self._write({"key": entry.key, "status": entry.status, "result": encode_result(entry.result),
                     "error": entry.error, "elapsed_s": float(entry.elapsed_s)})
        self.entries[entry.key] = entry

    def extend(self, entries: Iterable[JournalEntry]) -> None:
        """Append several entries.

        Parameters
        ----------
        entries : Iterable[JournalEntry]
            The finished runs.
        """
        for entry in entries:
            self.append(entry)

    def close(self) -> None:
        """Close the file (entries stay readable in :attr:`entries`)."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def __enter__(self) -> "Journal":
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()
