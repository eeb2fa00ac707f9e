"""Readers for the strong-motion networks' one-component ASCII files: NIED K-NET/KiK-net and ESM.

These are the files most users download besides PEER NGA ``.AT2`` (read by :mod:`records.readers`):
K-NET/KiK-net and ESM files hold **one component** each, and a pair runs as ``EW+NS`` (see
:func:`records.resolve.resolve_record`). Both readers return a :class:`records.Record` in m/s²
and refuse in one line what would be silently wrong: a vertical component (the building is
excited horizontally), a velocity or displacement history, a value count that disagrees with
the header, a scale or unit that does not reproduce the header's own peak acceleration.

``knet`` — NIED K-NET and KiK-net ASCII (``*.EW``, ``*.NS``, ``*.UD``; KiK-net ``*.EW1``,
``*.NS2``, ...; National Research Institute for Earth Science and Disaster Resilience,
https://www.kyoshin.bosai.go.jp). Seventeen header lines, each a label then a value::

    Origin Time       2011/03/11 14:46:00
    ...
    Station Code      MYG004
    Record Time       2011/03/11 14:46:24
    Sampling Freq(Hz) 100Hz
    Duration Time(s)  300
    Dir.              N-S
    Scale Factor      3920(gal)/6182761
    Max. Acc. (gal)   2699.995
    Last Correction   2011/03/11 14:46:09
    Memo.

then integer counts, eight per line. The acceleration is ``counts × 3920 / 6182761`` gal. The
counts carry the logger's offset, so the mean of the record is removed (NIED's own advice for
these files; the offset is kept in ``metadata["offset_removed_m_s2"]``). ``Dir.`` is ``N-S``,
``E-W`` or ``U-D`` (K-NET), or ``1``-``6`` (KiK-net: 1-3 borehole, 4-6 surface, each N-S, E-W,
U-D). The labels are read by label, not by line number, and ``Max. Acc. (gal)`` must agree with
the converted counts (with or without the offset) within :data:`PEAK_TOLERANCE`: a misread scale
factor would otherwise pass as a record 100 times too strong.

``esm`` — the Engineering Strong Motion database's ASCII files (ESM, ORFEUS; Luzi et al. 2016,
https://esm-db.eu), one ``KEY: value`` per header line (64 lines in the database's files) then one
value per line. Read: ``SAMPLING_INTERVAL_S``, ``NDATA`` (must equal the count), ``UNITS``
(``cm/s^2``), ``DATA_TYPE`` (only ``ACCELERATION``), ``STREAM`` (``HNE``, ``HGN``, ...; a
last letter ``Z`` is the vertical), ``STATION_CODE``, ``NETWORK``, ``EVENT_NAME``, ``EVENT_ID``,
and ``PGA_CM/S^2``, checked like K-NET's peak.

``cosmos`` — COSMOS V1/V2 files (the Center for Engineering Strong Motion Data, USGS NSMP,
CGS CSMIP: ``.V1``, ``.V2``, ``.V2c``), one or more channels per file: :func:`read_cosmos`. V0
files (raw counts) are refused.

References: COSMOS Strong-Motion Data Format, v1.20 (Consortium of Organizations for Strong-Motion
Observation Systems, 2001). Aoi, S. et al. (2004) Strong-motion seismograph network operated by NIED: K-NET and
KiK-net. J. Japan Assoc. Earthq. Eng. 4(3), 65-74. Luzi, L. et al. (2016) The Engineering
Strong-Motion Database: a platform to access Pan-European accelerometric data. Seismol. Res.
Lett. 87(4), 987-997.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np

from benchmark.foundation.errors import InputError
from records.file_values import (build_record, canonical_units, check_dt, is_vertical_label, parse_number, read_lines,
                                 to_si, unit_factor)
from records.record import Record

__all__ = ["read_knet", "read_esm", "read_cosmos", "is_knet", "is_esm", "is_cosmos", "PEAK_TOLERANCE",
           "STATION_SUFFIXES"]

#: Relative agreement asked between a header's peak acceleration and the values read: wide enough
#: for the header's rounding and for how the network removed the offset, far below the factor of
#: ten or more that a misread scale factor or unit gives.
PEAK_TOLERANCE = 0.10

#: Suffixes of the networks' component files (K-NET, KiK-net surface and borehole, ESM ASCII).
STATION_SUFFIXES = frozenset({".ew", ".ns", ".ud", ".ew1", ".ns1", ".ud1", ".ew2", ".ns2", ".ud2", ".asc",
                              ".v1", ".v2", ".v1c", ".v2c"})

_KNET_LABELS = {
    "station": "Station Code", "freq": "Sampling Freq(Hz)", "duration": "Duration Time(s)",
    "dir": "Dir.", "scale": "Scale Factor", "peak": "Max. Acc. (gal)", "origin": "Origin Time",
    "record_time": "Record Time", "magnitude": "Mag.",
}
#: K-NET's ``Dir.`` values and KiK-net's channel numbers (1-3 borehole, 4-6 surface).
_KNET_DIRECTIONS = {"N-S": "NS", "E-W": "EW", "U-D": "UD", "1": "NS", "2": "EW", "3": "UD",
                    "4": "NS", "5": "EW", "6": "UD"}
_SCALE = re.compile(r"^\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*\(\s*gal\s*\)\s*/\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*$",
                    re.IGNORECASE)
_HEADER_LINES_KNET = 17


def is_knet(lines: list[str]) -> bool:
    """True when ``lines`` open like a K-NET/KiK-net ASCII file (``Origin Time`` first, then a
    ``Scale Factor`` line within the header).

    Parameters
    ----------
    lines : list of str
        The file's lines.
    """
    head = [line.strip() for line in lines[:_HEADER_LINES_KNET + 3]]
    return bool(head) and head[0].startswith("Origin Time") and any(h.startswith("Scale Factor") for h in head)


def is_esm(lines: list[str]) -> bool:
    """True when ``lines`` open like an ESM ASCII file (``EVENT_NAME:`` first, or a
    ``SAMPLING_INTERVAL_S:`` key within the first 80 lines).

    Parameters
    ----------
    lines : list of str
        The file's lines.
    """
    head = [line.strip() for line in lines[:80]]
    return bool(head) and (head[0].startswith("EVENT_NAME:") or any(h.startswith("SAMPLING_INTERVAL_S:") for h in head))


def _check_peak(path: Path, values_si: np.ndarray, offset_si: float, header_peak: float | None,
                label: str) -> None:
    """Refuse a file whose converted values do not reproduce the header's own peak."""
    if header_peak is None or header_peak == 0.0:
        return
    header_peak = abs(header_peak)  # ESM's PGA_CM/S^2 carries the peak's sign
    peaks = (float(np.max(np.abs(values_si))), float(np.max(np.abs(values_si + offset_si))))
    if min(abs(p / header_peak - 1.0) for p in peaks) > PEAK_TOLERANCE:
        raise InputError(f"{path}: the values read give a peak of {peaks[0] * 100:.4g} cm/s² but the header's "
                         f"{label} says {header_peak * 100:.4g} cm/s²; a misread scale or unit (the file is "
                         "refused rather than run at the wrong strength)")


def _refuse_vertical(path: Path, where: str, value: str, pair_hint: str) -> None:
    raise InputError(f"{where}: a vertical component ({value}); the building is excited horizontally: "
                     f"give the two horizontal files as a pair, e.g. {pair_hint}")


def read_knet(path: str | os.PathLike, name: str | None = None) -> Record:
    """Read one component of a NIED K-NET or KiK-net ASCII file (module docstring).

    Parameters
    ----------
    path : path-like
        The file (``MYG0041103111446.EW``, ``IWTH251103111446.NS2``, ...).
    name : str, optional
        Record name (default: the station code and the file's suffix, e.g. ``MYG004.EW``).

    Returns
    -------
    Record
        One component in m/s², the record's mean removed, labelled ``EW`` or ``NS``; the header's
        station, origin time, magnitude and record time in ``metadata``.

    Raises
    ------
    InputError
        A missing header label, a scale factor not of the form ``N(gal)/M``, a vertical component,
        a value count more than one second away from the header's duration, a value that is not
        an integer count, or a peak that disagrees with ``Max. Acc. (gal)``.
    """
    path, lines = read_lines(path)
    where = str(path)
    fields: dict[str, tuple[str, int]] = {}
    data_start = None
    for lineno, line in enumerate(lines[:_HEADER_LINES_KNET + 3], start=1):
        stripped = line.strip()
        if stripped.startswith("Memo."):
            data_start = lineno  # the last header line; the counts follow
            break
        for key, label in _KNET_LABELS.items():
            if stripped.startswith(label):
                fields[key] = (stripped[len(label):].strip(), lineno)
    if data_start is None:
        raise InputError(f"{where}: no 'Memo.' line within the first {_HEADER_LINES_KNET + 3} lines; a K-NET/KiK-net "
                         f"file has {_HEADER_LINES_KNET} header lines, the last 'Memo.'")
    for key in ("freq", "duration", "dir", "scale"):
        if key not in fields:
            raise InputError(f"{where}: the header has no {_KNET_LABELS[key]!r} line (K-NET/KiK-net header)")
    freq_text, freq_line = fields["freq"]
    freq = parse_number(re.sub(r"(?i)hz$", "", freq_text).strip(), path, freq_line, "the sampling frequency in Hz")
    if freq <= 0:
        raise InputError(f"{where}:{freq_line}: sampling frequency {freq_text!r}; expected a positive number of Hz")
    dt = check_dt(1.0 / freq, f"{where}:{freq_line}")
    direction_text, dir_line = fields["dir"]
    direction = _KNET_DIRECTIONS.get(direction_text.split()[0] if direction_text else "")
    if direction is None:
        raise InputError(f"{where}:{dir_line}: direction {direction_text!r}; expected N-S, E-W, U-D or a KiK-net "
                         "channel 1-6")
    if direction == "UD":
        digit = path.suffix[-1] if path.suffix[-1:].isdigit() else ""  # KiK-net's .UD1 / .UD2
        stem = path.with_suffix("").name
        _refuse_vertical(path, f"{where}:{dir_line}", f"Dir. {direction_text}",
                         f"{stem}.EW{digit}+{stem}.NS{digit}")
    scale_text, scale_line = fields["scale"]
    m = _SCALE.match(scale_text)
    if not m:
        raise InputError(f"{where}:{scale_line}: scale factor {scale_text!r}; expected 'N(gal)/M' (counts to gal)")
    numerator, denominator = float(m.group(1)), float(m.group(2))
    if numerator <= 0 or denominator <= 0:
        raise InputError(f"{where}:{scale_line}: scale factor {scale_text!r}; both parts must be positive")

    counts: list[float] = []
    for lineno, line in enumerate(lines[data_start:], start=data_start + 1):
        for token in line.split():
            value = parse_number(token, path, lineno, "integer counts (K-NET data)")
            if value != int(value):
                raise InputError(f"{where}:{lineno}: {token!r} is not an integer count; K-NET/KiK-net data are counts")
            counts.append(value)
    duration_text, duration_line = fields["duration"]
    duration = parse_number(duration_text, path, duration_line, "the duration in seconds")
    expected = duration * freq
    if len(counts) < 2 or abs(len(counts) - expected) > freq:  # Duration Time is in whole seconds
        raise InputError(f"{where}: the header says {duration_text} s at {freq:g} Hz ({expected:.0f} samples) but the "
                         f"file holds {len(counts)} values (truncated or joined?)")
    gal = to_si(counts, numerator / denominator)  # counts -> gal
    offset = float(np.mean(gal))
    acceleration = (gal - offset) * unit_factor("gal")
    peak = None
    if "peak" in fields:
        peak_text, peak_line = fields["peak"]
        peak = parse_number(peak_text, path, peak_line, "the peak acceleration in gal") * unit_factor("gal")
    _check_peak(path, acceleration, offset * unit_factor("gal"), peak, "Max. Acc. (gal)")
    station = fields.get("station", ("", 0))[0] or path.stem
    metadata = {"format": "knet", "units_in_file": "counts", "units_from": f"header scale factor {scale_text}",
                "offset_removed_m_s2": offset * unit_factor("gal"), "station": station,
                "direction": direction_text}
    channel = direction_text.split()[0]
    if channel.isdigit():  # KiK-net: channels 1-3 the borehole instrument, 4-6 the surface one
        metadata["sensor"] = "borehole" if int(channel) <= 3 else "surface"
    for key in ("origin", "record_time", "magnitude"):
        if key in fields:
            metadata[key] = fields[key][0]
    return build_record(path, name=name or f"{station}{path.suffix}", dt=dt, acceleration=acceleration,
                        labels=(direction,), source=str(path), metadata=metadata)


_ESM_KEY = re.compile(r"^([A-Z0-9_/^.()\-]+):(.*)$")


def read_esm(path: str | os.PathLike, units: str | None = None, name: str | None = None) -> Record:
    """Read one component of an ESM (Engineering Strong Motion database) ASCII file.

    Parameters
    ----------
    path : path-like
        The file (``IT.NRC..HGE.D.20161030.064018.C.ACC.ASC``, ...).
    units : str, optional
        Units of the values when the header's ``UNITS`` is empty; if both are given they must agree.
    name : str, optional
        Record name (default: ``NETWORK.STATION.STREAM``).

    Returns
    -------
    Record
        One component in m/s², labelled with the stream (``HGE``); event and station in metadata.

    Raises
    ------
    InputError
        A missing ``SAMPLING_INTERVAL_S``, a ``DATA_TYPE`` other than acceleration, a vertical
        stream, ``NDATA`` different from the count, or a peak that disagrees with ``PGA_CM/S^2``.
    """
    path, lines = read_lines(path)
    where = str(path)
    header: dict[str, tuple[str, int]] = {}
    data_start = len(lines)
    for lineno, line in enumerate(lines, start=1):
        stripped = line.strip()
        m = _ESM_KEY.match(stripped)
        if m:
            header[m.group(1)] = (m.group(2).strip(), lineno)
            continue
        if stripped:
            data_start = lineno - 1
            break
    if "SAMPLING_INTERVAL_S" not in header:
        raise InputError(f"{where}: no SAMPLING_INTERVAL_S in the header (ESM ASCII file)")
    data_type = header.get("DATA_TYPE", ("", 0))[0].upper()
    if data_type and data_type != "ACCELERATION":
        raise InputError(f"{where}:{header['DATA_TYPE'][1]}: DATA_TYPE {data_type!r}; expected an ACCELERATION history")
    stream, stream_line = header.get("STREAM", ("", 0))
    if stream and is_vertical_label(stream):
        stem = path.name
        _refuse_vertical(path, f"{where}:{stream_line}", f"STREAM {stream}",
                         f"{stem.replace(stream, stream[:-1] + 'E')}+{stem.replace(stream, stream[:-1] + 'N')}")
    dt_text, dt_line = header["SAMPLING_INTERVAL_S"]
    dt = check_dt(parse_number(dt_text, path, dt_line, "the sampling interval in s"), f"{where}:{dt_line}")
    file_units, units_line = header.get("UNITS", ("", 0))
    if file_units and units is not None and unit_factor(units, f"{where}: units argument") != unit_factor(file_units, f"{where}:{units_line}"):
        raise InputError(f"{where}:{units_line}: units {units!r} given but the header says {file_units!r}")
    if not file_units and units is None:
        raise InputError(f"{where}: the header's UNITS is empty; give the units (--units cm/s2, units='cm/s2')")
    chosen = file_units or units
    assert chosen is not None
    factor = unit_factor(chosen, f"{where}:{units_line}" if file_units else f"{where}: units argument")
    values: list[float] = []
    for lineno, line in enumerate(lines[data_start:], start=data_start + 1):
        for token in line.split():
            values.append(parse_number(token, path, lineno, "acceleration values (ESM data)"))
    if header.get("NDATA", ("", 0))[0]:
        ndata_text, ndata_line = header["NDATA"]
        ndata = parse_number(ndata_text, path, ndata_line, "NDATA (an integer)")
        if ndata != len(values):
            raise InputError(f"{where}: the header says NDATA = {ndata_text} but the file holds {len(values)} values")
    acceleration = to_si(values, factor)
    peak = None
    if header.get("PGA_CM/S^2", ("", 0))[0]:
        peak_text, peak_line = header["PGA_CM/S^2"]
        peak = parse_number(peak_text, path, peak_line, "the PGA in cm/s²") * unit_factor("cm/s2")
    _check_peak(path, acceleration, 0.0, peak, "PGA_CM/S^2")
    network, station = header.get("NETWORK", ("", 0))[0], header.get("STATION_CODE", ("", 0))[0]
    metadata = {"format": "esm", "units_in_file": canonical_units(chosen),
                "units_from": "header UNITS" if file_units else "argument", "station": station,
                "network": network, "stream": stream}
    for key, field in (("EVENT_NAME", "event_name"), ("EVENT_ID", "event_id"), ("PROCESSING", "processing"),
                       ("BASELINE_CORRECTION", "baseline_correction_in_file"),
                       ("DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS", "first_sample")):
        if header.get(key, ("", 0))[0]:
            metadata[field] = header[key][0]
    default_name = ".".join(p for p in (network, station, stream) if p) or path.stem
    return build_record(path, name=name or default_name, dt=dt, acceleration=acceleration,
                        labels=(stream or "component 1",), source=str(path), metadata=metadata)


# --------------------------------------------------------------------------- COSMOS V1/V2
#: The first line of a COSMOS channel block: ``Corrected acceleration (Format v01.20 with 13 text lines)``.
_COSMOS_START = re.compile(r"\(Format\s+v\d+\.\d+\s+with\s+(\d+)\s+text\s+lines\)", re.IGNORECASE)
_COSMOS_COUNT = re.compile(r"^\s*(\d+)\s+(Integer-header|Real-header|Comment)", re.IGNORECASE)
_COSMOS_DATA = re.compile(r"^\s*(\d+)\s+(acceleration|velocity|displacement)\s+pts,.*?units\s*=\s*([^(,]*?)\s*"
                          r"\((\d+)\)\s*,\s*Format\s*=\s*\((\d+)[A-Z](\d+)", re.IGNORECASE)
_COSMOS_FORMAT = re.compile(r"Format\s*=\s*\((\d+)[A-Z](\d+)", re.IGNORECASE)
#: COSMOS physical-unit codes of acceleration (COSMOS Strong-Motion Data Format v1.20, Table 2).
_COSMOS_UNITS = {2: "g", 4: "cm/s2", 10: "cm/s2", 11: None}
#: COSMOS orientation codes other than azimuths (Table 9).
_COSMOS_DIRECTIONS = {400: "Up", 401: "Down", 402: "Vertical", 500: "Radial", 501: "Transverse",
                      600: "Longitudinal", 601: "Tangential", 700: "H1", 701: "H2"}
#: COSMOS orientation codes of the vertical (Table 9: up, down, vertical).
_COSMOS_VERTICAL = (400, 401, 402)
#: 0-based indices in the headers (COSMOS v1.20, Tables 1 and 3; the units code and the sampling
#: interval in ms, record length in s, maximum in the data's units).
_INT_ORIENTATION, _REAL_DT_MS, _REAL_LENGTH, _REAL_MAX = 53, 61, 62, 63


def is_cosmos(lines: list[str]) -> bool:
    """True when ``lines`` open like a COSMOS V0/V1/V2 file (``(Format v01.20 with 13 text lines)``).

    Parameters
    ----------
    lines : list of str
        The file's lines.
    """
    return bool(lines) and _COSMOS_START.search(lines[0]) is not None


def _fortran_values(lines: list[str], start: int, count: int, per_line: int, width: int, path: Path,
                    what: str) -> tuple[list[float], int]:
    """``count`` fixed-width values from ``lines[start:]`` (Fortran ``(per_line F width.d)``: glued
    negative values are split by position, not by blanks); returns them and the next line."""
    values: list[float] = []
    i = start
    while len(values) < count:
        if i >= len(lines):
            raise InputError(f"{path}: {what}: {count} values announced, the file ends after {len(values)} "
                             "(truncated?)")
        line = lines[i].rstrip()
        for k in range(per_line):
            chunk = line[k * width:(k + 1) * width].strip()
            if chunk and len(values) < count:
                values.append(parse_number(chunk, path, i + 1, what))
        i += 1
    return values, i


def read_cosmos(path: str | os.PathLike, name: str | None = None) -> Record:
    """Read the horizontal acceleration channels of a COSMOS V1 or V2 file (CESMD, USGS NSMP).

    COSMOS Strong-Motion Data Format v1.20 (Consortium of Organizations for Strong-Motion
    Observation Systems, 2001): per channel, text lines (their number on line 1), an integer and
    a real header (their counts and Fortran formats on their own lines), comment lines, then
    ``N acceleration pts, approx S secs, units=cm/sec2(04),Format=(8F10.5)`` and the values,
    read by their fixed widths. The step is the real header's sampling interval (ms, value 62),
    checked against the record length (value 63); the units come from the data line's code; the
    header's maximum (value 64) must match the values read to :data:`PEAK_TOLERANCE`. A channel
    whose orientation code is vertical (400-402) or whose SCNL channel ends in Z is left out and
    said; velocity and displacement blocks are skipped.

    Parameters
    ----------
    path : path-like
        The file (``.V1``, ``.V2``, ``.V2c``).
    name : str, optional
        Record name (default: the file stem).

    Returns
    -------
    Record
        The file's horizontal acceleration channels [m/s²], labelled by azimuth (``340 deg``) or
        SCNL channel.

    Raises
    ------
    InputError
        A V0 file (raw counts), a malformed or truncated block, an unknown step or unit, channels
        at different steps, a peak that disagrees with the header, or only vertical channels.
    """
    path, lines = read_lines(path)
    where = str(path)
    if re.search(r"\bcounts\b", lines[0], re.IGNORECASE) or "raw" in lines[0].lower():
        raise InputError(f"{where}:1: a COSMOS V0 file (raw counts, {lines[0].split('(')[0].strip()!r}); give its V1 "
                         "or V2 file (corrected acceleration)")
    channels, skipped = [], []
    i = 0
    while i < len(lines):
        m = _COSMOS_START.search(lines[i])
        if not m:
            if lines[i].strip() and not re.search(r"end[\s-]+of[\s-]+data", lines[i], re.IGNORECASE):
                raise InputError(f"{where}:{i + 1}: expected a COSMOS block header '(Format v01.20 with N text "
                                 f"lines)' or the end of the file, found {lines[i].strip()[:60]!r}")
            i += 1
            continue
        block_line = i + 1
        text = lines[i:i + int(m.group(1))]
        unknown = -999.0
        um = re.search(r"unspecified:\s*(-?\d+)", " ".join(text))
        if um:
            unknown = float(um.group(1))
        i += int(m.group(1))
        headers: dict[str, list[float]] = {}
        comments: list[str] = []
        for kind in ("integer-header", "real-header", "comment"):
            cm = _COSMOS_COUNT.match(lines[i]) if i < len(lines) else None
            if not cm or cm.group(2).lower() != kind:
                raise InputError(f"{where}:{i + 1}: expected the {kind.replace('-', ' ')} line of a COSMOS block, "
                                 f"found {lines[i].strip()[:60] if i < len(lines) else 'the end of the file'!r}")
            count = int(cm.group(1))
            if kind == "comment":
                comments = lines[i + 1:i + 1 + count]
                i += 1 + count
                continue
            fm = _COSMOS_FORMAT.search(lines[i])
            if not fm:
                raise InputError(f"{where}:{i + 1}: no Format=(nIw) / (nFw.d) on the {kind} line")
            headers[kind], i = _fortran_values(lines, i + 1, count, int(fm.group(1)), int(fm.group(2)), path, kind)
        dm = _COSMOS_DATA.match(lines[i]) if i < len(lines) else None
        if not dm:
            raise InputError(f"{where}:{i + 1}: expected 'N acceleration pts, approx S secs, units=...(code),"
                             f"Format=(...)', found {lines[i].strip()[:70] if i < len(lines) else 'the end'!r}")
        npts, series, unit_text, code = int(dm.group(1)), dm.group(2).lower(), dm.group(3), int(dm.group(4))
        values, i = _fortran_values(lines, i + 1, npts, int(dm.group(5)), int(dm.group(6)), path, f"{series} values")
        ints, reals = headers["integer-header"], headers["real-header"]
        scnl = re.search(r"<SCNL>\s*([^\s.]+)\.([^\s.]+)", " ".join(comments))
        orientation = ints[_INT_ORIENTATION] if len(ints) > _INT_ORIENTATION else unknown
        label = scnl.group(2) if scnl else (f"{orientation:g} deg" if 0 <= orientation <= 360 else
                                             _COSMOS_DIRECTIONS.get(int(orientation), f"channel at line {block_line}"))
        if series != "acceleration":
            continue  # a V2 file's velocity and displacement blocks
        if orientation in _COSMOS_VERTICAL or (scnl and is_vertical_label(scnl.group(2))):
            skipped.append(f"{label} (vertical, block at line {block_line})")
            continue
        dt_ms = reals[_REAL_DT_MS] if len(reals) > _REAL_DT_MS else unknown
        if dt_ms == unknown:
            raise InputError(f"{where}:{block_line}: the real header gives no sampling interval (value 62 = {dt_ms:g})")
        dt = check_dt(dt_ms / 1000.0, f"{where}:{block_line}")
        length = reals[_REAL_LENGTH] if len(reals) > _REAL_LENGTH else unknown
        if length != unknown and abs(length - npts * dt) > 1.5 * dt:
            raise InputError(f"{where}:{block_line}: {npts} values at {dt:g} s last {npts * dt:g} s, the header says "
                             f"{length:g} s")
        units = _COSMOS_UNITS.get(code)
        try:
            factor = unit_factor(units or unit_text, f"{where}:{block_line}: units")
        except InputError:
            raise InputError(f"{where}:{block_line}: units {unit_text!r} (code {code}); expected an acceleration in "
                             "g or cm/s²") from None
        acceleration = to_si(values, factor)
        peak = reals[_REAL_MAX] if len(reals) > _REAL_MAX and reals[_REAL_MAX] != unknown else None
        _check_peak(path, acceleration, 0.0, None if peak is None else peak * factor, "maximum (real value 64)")
        channels.append((label, dt, acceleration, units or unit_text))
    if not channels:
        raise InputError(f"{where}: no horizontal acceleration channel" + (f" ({'; '.join(skipped)})" if skipped else "")
                         + "; the building is excited horizontally")
    steps = {c[1] for c in channels}
    if len(steps) > 1:
        raise InputError(f"{where}: channels sampled at {', '.join(f'{s:g}' for s in sorted(steps))} s; resample "
                         "them to one step")
    n = max(c[2].size for c in channels)
    acc = np.zeros((n, len(channels)))
    for k, c in enumerate(channels):
        acc[:c[2].size, k] = c[2]
    metadata = {"format": "cosmos", "units_in_file": canonical_units(channels[0][3]), "units_from": "file header"}
    if skipped:
        metadata["columns"] = "left out: " + ", ".join(skipped)
    return build_record(path, name=name or path.stem, dt=channels[0][1], acceleration=acc,
                        labels=tuple(c[0] for c in channels), source=str(path), metadata=metadata)
