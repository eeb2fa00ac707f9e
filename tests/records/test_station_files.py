"""K-NET/KiK-net and ESM component files, and pairs of one-component files (``X+Y``).

The files are written here in each network's published layout (``records/station_files.py`` cites
it) from a known acceleration, so each test knows what the reader must return. Nothing is
copied from the networks' data.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from records import load_record
from records.readers import detect_format
from records.resolve import looks_like_file, record_files, resolve_record

FS = 100.0
N = 3000
#: K-NET's scale factor of the 2011 records: counts * 3920 / 6182761 = gal
NUM, DEN = 3920, 6182761


def _motion(seed: int, n: int = N, peak_gal: float = 350.0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / FS
    a = np.convolve(rng.standard_normal(n), np.ones(5) / 5, "same") * np.exp(-((t - 10) / 5) ** 2)
    return a / np.abs(a).max() * peak_gal


def _knet(tmp_path, name, gal, direction="E-W", offset_counts=1234, peak=None, duration=None, scale=None,
          freq="100Hz"):
    rng = np.random.default_rng(7)
    # a logger's offset and a few counts of noise, as in the networks' files
    counts = np.round(gal * DEN / NUM + offset_counts + rng.integers(-2, 3, gal.size)).astype(int)
    scaled = counts * NUM / DEN
    if peak is None:
        peak = np.abs(scaled - scaled.mean()).max()
    header = (f"Origin Time       2011/03/11 14:46:00\nLat.              38.103\nLong.             142.860\n"
              f"Depth. (km)       24\nMag.              9.0\nStation Code      MYG004\n"
              f"Station Lat.      38.7291\nStation Long.     141.0217\nStation Height(m) 230\n"
              f"Record Time       2011/03/11 14:46:24\nSampling Freq(Hz) {freq}\n"
              f"Duration Time(s)  {duration if duration is not None else gal.size / FS:g}\nDir.              {direction}\n"
              f"Scale Factor      {scale or f'{NUM}(gal)/{DEN}'}\nMax. Acc. (gal)   {peak:.3f}\n"
              f"Last Correction   2011/03/11 14:46:09\nMemo.\n")
    rows = [" ".join(f"{c:8d}" for c in counts[i:i + 8]) for i in range(0, counts.size, 8)]
    path = tmp_path / name
    path.write_text(header + "\n".join(rows) + "\n")
    return path, (scaled - scaled.mean()) * 0.01


def _esm(tmp_path, name, gal, stream="HGE", **changes):
    header = {"EVENT_NAME": "CENTRAL_ITALY", "EVENT_ID": "EMSC-20161030_0000029", "NETWORK": "IT",
              "STATION_CODE": "NRC", "STATION_NAME": "NORCIA",
              "DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS": "20161030_064018.000", "SAMPLING_INTERVAL_S": "0.010000",
              "NDATA": str(gal.size), "STREAM": stream, "UNITS": "cm/s^2", "PGA_CM/S^2": f"{np.abs(gal).max():.6f}",
              "VS30_M/S": "", "DATA_TYPE": "ACCELERATION", "DATA_CITATION": "https://doi.org/10.13127/esm",
              "USER5": ""}
    header.update(changes)
    path = tmp_path / name
    path.write_text("".join(f"{k}: {v}\n" for k, v in header.items()) + "".join(f"{v:.6E}\n" for v in gal))
    return path


def _refused(spec, words, **kwargs):
    with pytest.raises(InputError) as info:
        if "+" in str(spec):
            resolve_record(str(spec), **kwargs)
        else:
            load_record(spec, **kwargs)
    message = str(info.value)
    assert "\n" not in message and words in message, message
    return message


def test_knet_counts_are_scaled_to_si_and_the_loggers_offset_removed(tmp_path):
    gal = _motion(1)
    path, expected = _knet(tmp_path, "MYG0041103111446.EW", gal)
    assert detect_format(path) == "knet"
    rec = load_record(path)
    assert rec.dt == pytest.approx(1 / FS) and rec.labels == ("EW",) and rec.name == "MYG004.EW"
    # exact up to float rounding: the counts are integers and the reader applies the header's ratio
    np.testing.assert_allclose(rec.acceleration[:, 0], expected, rtol=0, atol=1e-12)
    # the offset removed is the logger's (1234 counts) plus the motion's own mean, to the rounding of counts
    assert rec.metadata["offset_removed_m_s2"] == pytest.approx((1234 * NUM / DEN + gal.mean()) * 0.01, abs=1e-5)
    assert rec.metadata["origin"] == "2011/03/11 14:46:00" and "counts" in rec.summary()["units_assumed"]


@pytest.mark.parametrize("channel,label", [("4", "NS"), ("5", "EW"), ("1", "NS"), ("2", "EW")])
def test_kiknet_channel_numbers_name_the_direction(tmp_path, channel, label):
    path, _ = _knet(tmp_path, f"IWTH251103111446.X{channel}", _motion(2), direction=channel)
    assert load_record(path).labels == (label,)


@pytest.mark.parametrize("direction", ["U-D", "3", "6"])
def test_a_vertical_knet_file_is_refused_with_the_pair_to_give(tmp_path, direction):
    path, _ = _knet(tmp_path, "MYG0041103111446.UD", _motion(3), direction=direction)
    message = _refused(path, "vertical component")
    assert "MYG0041103111446.EW+MYG0041103111446.NS" in message


def test_a_knet_scale_factor_that_does_not_reproduce_the_header_peak_is_refused(tmp_path):
    # a peak 100 times the counts' (a scale written in another unit) must not run silently
    path, _ = _knet(tmp_path, "bad.EW", _motion(4), peak=35000.0)
    _refused(path, "misread scale or unit")


@pytest.mark.parametrize("change,words", [
    ({"duration": 60}, "truncated or joined"),
    ({"scale": "3920/6182761"}, "expected 'N(gal)/M'"),
    ({"freq": "0Hz"}, "sampling frequency"),
])
def test_malformed_knet_headers_are_refused_in_one_line(tmp_path, change, words):
    path, _ = _knet(tmp_path, "m.EW", _motion(5), **change)
    _refused(path, words)


def test_a_knet_value_that_is_not_a_count_is_refused_with_its_line(tmp_path):
    path, _ = _knet(tmp_path, "f.EW", _motion(6))
    lines = path.read_text().splitlines()
    lines[20] = lines[20].replace(lines[20].split()[0], "12.5", 1)
    path.write_text("\n".join(lines) + "\n")
    assert ":21:" in _refused(path, "not an integer count")


def test_esm_file_is_read_with_its_units_stream_and_event(tmp_path):
    gal = _motion(7)
    path = _esm(tmp_path, "IT.NRC..HGE.D.20161030.064018.C.ACC.ASC", gal)
    assert detect_format(path) == "esm"
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[:, 0], np.array([float(f"{v:.6E}") for v in gal]) * 0.01,
                               rtol=1e-12)
    assert rec.labels == ("HGE",) and rec.name == "IT.NRC.HGE" and rec.dt == pytest.approx(0.01)
    assert rec.metadata["event_name"] == "CENTRAL_ITALY"


@pytest.mark.parametrize("change,words", [
    ({"DATA_TYPE": "VELOCITY", "UNITS": "cm/s"}, "expected an ACCELERATION history"),
    ({"NDATA": "2999"}, "NDATA = 2999"),
    ({"STREAM": "HGZ"}, "vertical component"),
    ({"PGA_CM/S^2": "3.5"}, "misread scale or unit"),
    ({"UNITS": ""}, "UNITS is empty"),
    ({"SAMPLING_INTERVAL_S": "10"}, "time step"),
])
def test_esm_files_that_would_be_silently_wrong_are_refused(tmp_path, change, words):
    _refused(_esm(tmp_path, "e.ASC", _motion(8), **change), words)


def test_esm_peaks_are_signed_and_blank_ndata_is_allowed(tmp_path):
    # ESM writes PGA_CM/S^2 with the peak's sign: the check must compare magnitudes, not skip
    gal = _motion(20)
    signed = -float(np.abs(gal).max())
    assert load_record(_esm(tmp_path, "a.ASC", gal, **{"PGA_CM/S^2": f"{signed:.6f}", "NDATA": ""})).n_samples == N
    _refused(_esm(tmp_path, "b.ASC", gal, **{"PGA_CM/S^2": "-3.0"}), "misread scale or unit")


def test_kiknet_borehole_and_surface_components_are_not_paired(tmp_path):
    ew1, _ = _knet(tmp_path, "IWTH251103111446.EW1", _motion(21), direction="2")
    ns2, _ = _knet(tmp_path, "IWTH251103111446.NS2", _motion(22), direction="4")
    _refused(f"{ew1}+{ns2}", "a borehole sensor")
    ud2, _ = _knet(tmp_path, "IWTH251103111446.UD2", _motion(23), direction="6")
    assert "IWTH251103111446.EW2+IWTH251103111446.NS2" in _refused(ud2, "vertical component")


def test_a_vertical_peer_component_is_never_run(tmp_path):
    g = _motion(24) / 981
    h1, up = _at2(tmp_path, "RSN_H1.AT2", g, "228"), _at2(tmp_path, "RSN_UP.AT2", g, "UP")
    _refused(f"{h1}+{up}", "is the vertical")
    with pytest.raises(InputError, match="is the vertical"):
        resolve_record(str(up))


def test_an_esm_file_without_units_reads_with_units_given(tmp_path):
    gal = _motion(9)
    rec = load_record(_esm(tmp_path, "e.ASC", gal, UNITS=""), units="cm/s2")
    assert np.abs(rec.acceleration).max() == pytest.approx(np.abs(gal).max() * 0.01, rel=1e-6)


def _at2(tmp_path, name, g, component, dt=0.01):
    path = tmp_path / name
    rows = [" ".join(f"{v:15.7E}" for v in g[i:i + 5]) for i in range(0, g.size, 5)]
    path.write_text(f"PEER NGA STRONG MOTION DATABASE RECORD\nNorthridge-01, 1/17/1994, Rinaldi, {component}\n"
                    f"ACCELERATION TIME SERIES IN UNITS OF G\nNPTS= {g.size}, DT= {dt:.4f} SEC\n" + "\n".join(rows) + "\n")
    return path


def test_a_pair_of_at2_files_runs_as_one_record_the_first_on_x(tmp_path):
    gx, gy = _motion(10) / 981, _motion(11, n=N - 3) / 981
    x, y = _at2(tmp_path, "RSN1063_H1.AT2", gx, "228"), _at2(tmp_path, "RSN1063_H2.AT2", gy, "318")
    spec = f"{x}+{y}"
    assert looks_like_file(spec) and record_files(spec) == [x, y]
    fn = resolve_record(spec, "FN-x")
    assert fn.labels == ("228", "318") and fn.n_samples == N
    np.testing.assert_allclose(fn.acceleration[:, 0], gx * 9.80665, rtol=1e-6)
    # the shorter component is padded with zeros at its end, and the record says so
    assert np.all(fn.acceleration[N - 3:, 1] == 0.0) and "3 samples shorter" in fn.metadata["columns"]
    fp = resolve_record(spec, "FP-x")
    np.testing.assert_array_equal(fp.acceleration[:, 0], fn.acceleration[:, 1])


def test_a_knet_pair_keeps_its_station_and_esm_pair_its_first_sample(tmp_path):
    ew, _ = _knet(tmp_path, "MYG0041103111446.EW", _motion(12))
    ns, _ = _knet(tmp_path, "MYG0041103111446.NS", _motion(13), direction="N-S")
    rec = resolve_record(f"{ew}+{ns}")
    assert rec.name == "MYG004" and rec.labels == ("EW", "NS") and rec.metadata["station"] == "MYG004"
    e = _esm(tmp_path, "e.ASC", _motion(14))
    n = _esm(tmp_path, "n.ASC", _motion(15), stream="HGN")
    assert resolve_record(f"{e}+{n}").metadata["first_sample"] == "20161030_064018.000"


def test_pairs_that_are_not_two_horizontal_components_together_are_refused(tmp_path):
    g = _motion(16) / 981
    a = _at2(tmp_path, "a.AT2", g, "228")
    b = _at2(tmp_path, "b.AT2", g, "228")
    _refused(f"{a}+{b}", "both component '228'")
    c = _at2(tmp_path, "c.AT2", g, "318", dt=0.005)
    _refused(f"{a}+{c}", "resample one")
    _refused(f"{a}+{b}+{c}", "two files, the first on x")
    e = _esm(tmp_path, "e.ASC", _motion(17))
    n = _esm(tmp_path, "n.ASC", _motion(18), stream="HGN", DATE_TIME_FIRST_SAMPLE_YYYYMMDD_HHMMSS="20161030_064019.000")
    _refused(f"{e}+{n}", "must start together")
    two = tmp_path / "two.csv"
    two.write_text("t,ax,ay\n" + "".join(f"{i * 0.01},{v},{v}\n" for i, v in enumerate(g)))
    _refused(f"{two}+{a}", "holds 2 components")


def test_a_file_whose_name_holds_a_plus_is_one_file(tmp_path):
    path = _at2(tmp_path, "RSN+1.AT2", _motion(19) / 981, "228")
    assert record_files(str(path)) == [path]
    assert resolve_record(str(path)).labels == ("228", "zero")


def _cosmos_block(gal, orientation, dt=0.01, units=("cm/sec2", 4), peak=None, length=None, scnl=None):
    """One COSMOS v1.20 channel block, written in the format's fixed widths (COSMOS Strong-Motion
    Data Format v1.20, 2001): 13 text lines, 100 integers (10I8), 100 reals (5F15.6), comments,
    then the values in (8F10.5), whose full-width negative values touch their neighbours."""
    ints = [-999] * 100
    ints[0], ints[1], ints[53] = 2, 1, orientation
    reals = [-999.0] * 100
    reals[61] = dt * 1000.0
    reals[62] = length if length is not None else gal.size * dt
    reals[63] = peak if peak is not None else float(gal[np.argmax(np.abs(gal))])
    text = ["Corrected acceleration    (Format v01.20 with 13 text lines) Src: written by a test"]
    text += [f"text line {k}" for k in range(2, 13)]
    text += ["Values used when parameter or data value is unknown/unspecified:   -999, -999.0"]
    out = text + [" 100 Integer-header values follow on  10 lines, Format= (10I8)"]
    out += ["".join(f"{v:8d}" for v in ints[k:k + 10]) for k in range(0, 100, 10)]
    out += [" 100 Real-header values follow on  20 lines, Format= (5F15.6)"]
    out += ["".join(f"{v:15.6f}" for v in reals[k:k + 5]) for k in range(0, 100, 5)]
    comments = [f"|<SCNL>STA.{scnl}.NP.--"] if scnl else []
    out += [f"  {len(comments)} Comment line(s) follow, each starting with a \"|\":"] + comments
    out += [f"  {gal.size:6d}  acceleration pts, approx {gal.size * dt:4.0f} secs, units={units[0]}({units[1]:02d}),"
            "Format=(8F10.5)"]
    out += ["".join(f"{v:10.5f}" for v in gal[k:k + 8]) for k in range(0, gal.size, 8)]
    return out + [f"/&  ----------  End of data for channel  1  ----------"]


def test_cosmos_channels_are_read_by_their_fixed_widths_and_the_vertical_left_out(tmp_path):
    # negative values of 3 integer digits fill F10.5: "-998.12345-512.34567" has no blank between them
    x = _motion(30, peak_gal=999.0)
    y = _motion(31, peak_gal=800.0)
    z = _motion(32, peak_gal=500.0)
    path = tmp_path / "CE23583.V2"
    path.write_text("\n".join(_cosmos_block(z, 400) + _cosmos_block(x, 360) + _cosmos_block(y, 90)) + "\n")
    import re
    assert re.search(r"\d-\d", path.read_text()), "the test must contain glued values"
    assert detect_format(path) == "cosmos"
    rec = load_record(path)
    assert rec.labels == ("360 deg", "90 deg") and rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.acceleration[:, 0], np.round(x, 5) * 0.01, atol=1e-12)
    assert "Up (vertical" in rec.metadata["columns"]


@pytest.mark.parametrize("change,words", [
    ({"peak": 19.99}, "misread scale or unit"),
    ({"length": 60.0}, "the header says 60 s"),
    ({"units": ("in/sec2", 7)}, "expected an acceleration in g or cm/s²"),
])
def test_cosmos_files_that_would_be_silently_wrong_are_refused(tmp_path, change, words):
    path = tmp_path / "c.V2"
    path.write_text("\n".join(_cosmos_block(_motion(33), 0, **change)) + "\n")
    _refused(path, words)


def test_cosmos_raw_counts_only_vertical_and_truncated_files_are_refused(tmp_path):
    path = tmp_path / "raw.V0"
    block = _cosmos_block(_motion(34), 0)
    block[0] = block[0].replace("Corrected acceleration", "Raw acceleration counts")
    path.write_text("\n".join(block) + "\n")
    _refused(path, "a COSMOS V0 file")
    path.write_text("\n".join(_cosmos_block(_motion(35), 0, scnl="HNZ")) + "\n")
    _refused(path, "no horizontal acceleration channel")
    path.write_text("\n".join(_cosmos_block(_motion(36), 0)[:-200]) + "\n")
    _refused(path, "the file ends after")
    rec = load_record(_write_g(tmp_path))
    assert rec.metadata["units_in_file"] == "g"


def _write_g(tmp_path):
    path = tmp_path / "g.V2"
    path.write_text("\n".join(_cosmos_block(_motion(37, peak_gal=0.5), 90, units=("g", 2))) + "\n")
    return path
