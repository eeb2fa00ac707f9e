"""Unusual and malformed record files: read right, or refused in one line naming the file.

Each case is a file a user could bring (a spreadsheet export, a headerless time column, a PEER
file with glued Fortran columns, a velocity history) that was once misread silently or refused
with a misleading message.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from records import STANDARD_GRAVITY, load_record
from records.readers import detect_format, read_at2

G = STANDARD_GRAVITY


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _refused(path, words, **kwargs):
    with pytest.raises(InputError) as info:
        load_record(path, **kwargs)
    message = str(info.value)
    assert str(path) in message and "\n" not in message and words in message, message
    return message


def test_headerless_time_column_sampled_unevenly_is_not_read_as_acceleration(tmp_path):
    # the first column increases throughout: it is time (once read as two cm/s² components)
    t = np.arange(60) * 0.01
    t[30:] += 0.004
    path = _write(tmp_path, "uneven.txt", "".join(f"{a:.3f} {0.1 * np.sin(a):.4f}\n" for a in t))
    assert detect_format(path) == "csv"
    _refused(path, "expected uniform sampling")


def test_headerless_time_and_two_components(tmp_path):
    path = _write(tmp_path, "three.txt", "".join(f"{0.02 * i:.2f} {i % 3 - 1} {1 - i % 3}\n" for i in range(10)))
    rec = load_record(path)
    assert rec.dt == pytest.approx(0.02) and rec.acceleration.shape == (10, 2)


def test_semicolons_with_decimal_commas_read_as_numbers(tmp_path):
    path = _write(tmp_path, "euro.csv", "time;ax [g]\n0,00;0,10\n0,01;-0,20\n0,02;0,05\n")
    rec = load_record(path)
    assert rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.acceleration[:, 0], np.array([0.1, -0.2, 0.05]) * G)


def test_one_value_per_line_with_decimal_commas_is_not_time_and_acceleration(tmp_path):
    # "1,5" was read as t = 1 s, a = 5 m/s²
    path = _write(tmp_path, "dc.txt", "1,5\n2,5\n3,5\n4,5\n")
    _refused(path, "decimal comma")


def test_quoted_cells_and_a_delimiter_ending_every_line(tmp_path):
    path = _write(tmp_path, "export.csv", '"time","ax",\n"0.00","1.0",\n"0.01","2.0",\n"0.02","-1.0",\n')
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[:, 0], [1.0, 2.0, -1.0])
    assert rec.labels == ("ax",)


@pytest.mark.parametrize("name, factor", [("acc_gal", 0.01), ("acc_cm_s2", 0.01), ("ax_m_s2", 1.0)])
def test_a_unit_as_the_suffix_of_a_column_name(tmp_path, name, factor):
    path = _write(tmp_path, "suffix.csv", f"time_s,{name}\n0,1\n0.01,2\n0.02,3\n")
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[:, 0], np.array([1.0, 2.0, 3.0]) * factor)
    assert rec.metadata["units_from"] == "file"


@pytest.mark.parametrize("header", ["time,vel (cm/s)", "time,v [m/s]", "time,disp_cm_s", "time,d (cm)"])
def test_a_velocity_or_displacement_column_is_refused(tmp_path, header):
    path = _write(tmp_path, "vel.csv", f"{header}\n0,1\n0.01,2\n0.02,3\n")
    _refused(path, "expected acceleration")


def test_a_row_of_units_under_the_names(tmp_path):
    path = _write(tmp_path, "units_row.csv", "time,ax,ay\ns,g,g\n0,0.1,0.2\n0.01,0.2,0.1\n")
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[0], np.array([0.1, 0.2]) * G)


def test_a_text_line_before_the_header_is_named(tmp_path):
    path = _write(tmp_path, "preamble.csv", "Station X\ntime,ax\n0,1\n0.01,2\n")
    assert ":1:" in _refused(path, "neither the header row nor data")


def test_header_and_data_with_different_separators(tmp_path):
    path = _write(tmp_path, "sep.csv", "time ax ay\n0,1,2\n0.01,2,3\n")
    _refused(path, "the header names 1 column(s) but the data rows have 3")


def test_benchmark_style_header_over_a_time_column(tmp_path):
    path = _write(tmp_path, "pct.txt", "% my quake. Acc. in cm/sec^2\n0.00 10\n0.01 20\n0.02 -10\n0.03 0\n")
    rec = load_record(path)
    assert rec.metadata["format"] == "csv" and rec.acceleration.shape == (4, 1)
    np.testing.assert_allclose(rec.acceleration[:, 0], [0.1, 0.2, -0.1, 0.0])


AT2_HEADER = ("PEER NGA STRONG MOTION DATABASE RECORD\nKOBE 01/16/95, KJMA, 000\n"
              "{kind} TIME SERIES IN UNITS OF {units}\nNPTS=    6, DT=   .0100 SEC\n")


def test_at2_values_glued_by_fortran_fixed_width(tmp_path):
    path = _write(tmp_path, "glued.AT2", AT2_HEADER.format(kind="ACCELERATION", units="G")
                  + "  1.0000000E-01-2.0000000E-01-3.0000000E-01\n -4.0000000E-01 5.0000000E-01-6.0000000E-01\n")
    rec = read_at2(path)
    np.testing.assert_allclose(rec.acceleration[:, 0], np.array([0.1, -0.2, -0.3, -0.4, 0.5, -0.6]) * G)


@pytest.mark.parametrize("name, kind", [("vel.VT2", "VELOCITY"), ("disp.AT2", "DISPLACEMENT")])
def test_peer_velocity_and_displacement_files_are_refused(tmp_path, name, kind):
    path = _write(tmp_path, name, AT2_HEADER.format(kind=kind, units="CM/S") + "1 2 3 4 5 6\n")
    _refused(path, kind.lower(), units="cm/s2")   # even with units given, it is not an acceleration


def test_values_no_unit_mix_up_explains_are_refused(tmp_path):
    path = _write(tmp_path, "huge.csv", "time,ax\n0,1\n0.01,1e300\n0.02,1\n")
    _refused(path, "sample 2 is 1e+300 m/s²")


# ---- cases from the review of the readers (each once misread or blamed on the wrong line)

def test_a_g_is_ground_acceleration_not_a_unit(tmp_path):
    # "a_g" names the ground acceleration; its units come from the comment (or the default)
    path = _write(tmp_path, "ag.csv", "time,a_g\n# units: m/s2\n0,1\n0.01,2\n0.02,3\n")
    rec = load_record(path)
    np.testing.assert_allclose(rec.acceleration[:, 0], [1.0, 2.0, 3.0])


def test_one_repeated_time_stamp_is_named_not_read_as_a_benchmark_file(tmp_path):
    t = np.arange(100) * 0.01
    t[80] = t[79]
    path = _write(tmp_path, "dup.txt", "".join(f"{a:.2f} {np.sin(7 * a):.4f}\n" for a in t))
    assert detect_format(path) == "csv"
    _refused(path, "does not increase")


def test_benchmark_header_keeps_its_two_columns_even_when_the_first_rises(tmp_path):
    rows = "".join(f"{0.1 * k:.3e} {0.05 * k:.3e}\n" for k in range(1, 40))
    path = _write(tmp_path, "excerpt.txt", "%A record, first column FN and second FP.\n"
                  "%Acc. in cm/sec^2 and dt=0.005 sec.\n" + rows)
    assert detect_format(path) == "benchmark"
    rec = load_record(path)
    assert rec.dt == pytest.approx(0.005) and rec.acceleration.shape == (39, 2)


@pytest.mark.parametrize("sep", [";", "\t", " "])
def test_decimal_commas_after_a_first_row_of_whole_numbers(tmp_path, sep):
    t = np.arange(50) * 0.01
    rows = "".join(f"{a:.2f}{sep}{np.sin(7 * a):.4f}\n".replace(".", ",") for a in t[1:])
    path = _write(tmp_path, "dc.txt", f"0{sep}0\n" + rows)
    rec = load_record(path, format="csv")
    assert rec.dt == pytest.approx(0.01)
    np.testing.assert_allclose(rec.acceleration[1:, 0], np.round(np.sin(7 * t[1:]), 4))


def test_a_bad_first_data_cell_is_named_on_its_own_line(tmp_path):
    path = _write(tmp_path, "na.csv", "time,ax\n0.0,NA\n0.01,0.1\n0.02,0.2\n")
    message = _refused(path, "'NA' is not a number")
    assert f"{path}:2:" in message


def test_a_unit_row_in_brackets(tmp_path):
    path = _write(tmp_path, "ur.csv", "time,ax\n[s],[g]\n0,1\n0.01,2\n0.02,3\n")
    np.testing.assert_allclose(load_record(path).acceleration[:, 0], np.array([1.0, 2.0, 3.0]) * G)


def test_acceleration_labels_in_parentheses_are_not_length_units(tmp_path):
    path = _write(tmp_path, "io.csv", "time,acc (in),acc (out)\n0,1,2\n0.01,2,3\n0.02,3,4\n")
    assert load_record(path).acceleration.shape == (3, 2)


def test_a_corrupt_at2_value_is_not_split_into_two(tmp_path):
    path = _write(tmp_path, "dots.AT2", AT2_HEADER.format(kind="ACCELERATION", units="G")
                  + "  1.2.3 0.4 0.5\n 0.1 0.2 0.3\n")
    _refused(path, "'1.2.3' is not a number")


def test_a_time_column_in_ms_read_as_s_is_refused(tmp_path):
    # times 0, 5, 10 ... under a header without a unit: a 5-s step, 10⁵ times the benchmark's
    # steps once interpolated (the run grew to 24 GB and was killed without a word)
    rows = "".join(f"{5 * k},{0.1 * np.sin(0.05 * k):.4f}\n" for k in range(400))
    path = _write(tmp_path, "time_ms.csv", "time,acc [m/s2]\n" + rows)
    _refused(path, "a step in ms given as s?")


def test_a_headerless_two_column_file_needs_its_step_and_says_its_unit_was_assumed(tmp_path):
    # read as the benchmark's format: a file at 0.01 s had run at 0.005 s (twice as fast) and
    # g read as cm/s² (981 times too weak), both said only inside the summary's units string
    from records.resolve import UNIT_NOT_STATED, resolve_record
    path = _write(tmp_path, "two.txt", "".join(f"{np.sin(0.1 * k):.4f} {np.cos(0.1 * k):.4f}\n" for k in range(200)))
    _refused(path, "no time step")
    rec = resolve_record(str(path), dt=0.01)
    assert rec.dt == 0.01 and any(UNIT_NOT_STATED in f for f in rec.metadata["flaws"])
    stated = resolve_record(str(path), dt=0.01, units="g")
    assert not any(UNIT_NOT_STATED in f for f in stated.metadata["flaws"])


@pytest.mark.parametrize("opener", ["zip", "gzip"])
def test_a_compressed_record_is_named_as_such(tmp_path, opener):
    # it had read as 'looks like a binary file (it holds NUL bytes)'
    import gzip
    import zipfile
    text = "".join(f"{0.005 * k:.3f},{np.sin(0.1 * k):.4f}\n" for k in range(100))
    path = tmp_path / f"rec.{opener}"
    if opener == "zip":
        with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
            z.writestr("rec.csv", text)
    else:
        path.write_bytes(gzip.compress(text.encode()))
    _refused(path, f"a {opener}")


# ------------------------------------------------------------------- what a file states of itself
# Probed 2026-11-28 (evening) with files as users write them: a single-column file whose comment
# said "units: m/s2" ran 9.81 times too strong (the comment was not read, the default g was), one
# stating "dt=0.01 s" was refused for lack of --dt, one under '%' comments or a column title was
# taken for another format and refused, and an AT2 step in milliseconds was read as seconds.
_WAVE = [0.3 * np.sin(0.2 * k) * np.exp(-0.002 * k) for k in range(800)]


def _single(lines_before, values=_WAVE):
    return "".join(line + "\n" for line in lines_before) + "".join(f"{v:.6f}\n" for v in values)


@pytest.mark.parametrize("header, dt, units, factor", [
    (["# El Centro 270, units: m/s2"], 0.01, None, 1.0),
    (["# Rinaldi 228, dt=0.01 s, units: cm/s2"], None, None, 0.01),
    (["% my record, acceleration in m/s^2, dt=0.02 sec"], None, None, 1.0),
    (["Acceleration (g)"], 0.01, None, STANDARD_GRAVITY),
    (["# units: g"], 0.01, "g", STANDARD_GRAVITY),
])
def test_a_single_column_file_reads_its_step_and_unit_from_its_comments(tmp_path, header, dt, units, factor):
    path = _write(tmp_path, "one.txt", _single(header))
    assert detect_format(path) == "single"
    rec = load_record(path, dt=dt, units=units)
    assert np.allclose(rec.acceleration[:, 0], np.asarray(_WAVE) * factor, rtol=0, atol=1e-6 * factor)  # 6 decimals written
    assert rec.dt == (dt or (0.02 if "0.02" in header[0] else 0.01))


def test_a_single_column_file_with_a_step_against_its_comments_is_refused(tmp_path):
    path = _write(tmp_path, "one.txt", _single(["# dt=0.01 s, units: m/s2"]))
    _refused(path, "given but the file says dt = 0.01 s", dt=0.02)
    assert load_record(path, units="g").metadata["units_from"] == "argument"  # --units wins over comments
    # a step stated nowhere is still asked for
    _refused(_write(tmp_path, "bare.txt", _single(["# El Centro"])), "give dt")


def test_an_at2_step_in_milliseconds_is_read_as_such(tmp_path):
    values = "".join(f"{v:15.7E}" + ("\n" if (k + 1) % 5 == 0 else "") for k, v in enumerate(_WAVE))
    path = _write(tmp_path, "ms.AT2", "PEER NGA STRONG MOTION DATABASE RECORD\nQuake, 1/1/2000, STA, 90\n"
                  "ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   800, DT=   10.0 MSEC\n" + values)
    assert read_at2(path).dt == pytest.approx(0.01)


def test_an_assumed_unit_is_a_warning_of_the_run(tmp_path):
    # the unit a format assumes is printed as a warning, not only kept in the results
    from records.resolve import UNIT_NOT_STATED, is_warning, resolve_record
    path = _write(tmp_path, "acc.csv", "time,acc\n" + "".join(f"{0.01 * k:.2f},{v:.6f}\n" for k, v in enumerate(_WAVE)))
    flaws = resolve_record(str(path)).metadata["flaws"]
    assert [f for f in flaws if is_warning(f)] and UNIT_NOT_STATED in flaws[0]
    assert not any(UNIT_NOT_STATED in f for f in resolve_record(str(path), units="m/s2").metadata["flaws"])


def test_free_comments_name_a_unit_only_where_they_state_it_and_units_wins(tmp_path):
    # a review: "# converted from cm/s2 to g" had made the values cm/s² (981 times too weak) and
    # refused --units g; in free comments a unit counts only where stated as the values', and a
    # --units argument wins over them ("in cm/s2, scaled to g" states a unit the values lost)
    converted = _write(tmp_path, "conv.txt", _single(["# converted from cm/s2 to g"]))
    rec = load_record(converted, dt=0.01)
    assert rec.metadata["units_from"].startswith("default")  # stated nowhere: the default, warned
    scaled = _write(tmp_path, "scaled.txt", _single(["# original record in cm/s2, scaled by 0.01 to g"]))
    assert load_record(scaled, dt=0.01).metadata["units_in_file"] == "cm/s2"
    rec = load_record(scaled, dt=0.01, units="g")
    assert rec.metadata["units_from"] == "argument"
    assert np.allclose(rec.acceleration[:, 0], np.asarray(_WAVE) * STANDARD_GRAVITY, atol=1e-5)


def test_an_at2_step_glued_to_its_unit_is_read(tmp_path):
    values = "".join(f"{v:15.7E}" + ("\n" if (k + 1) % 5 == 0 else "") for k, v in enumerate(_WAVE))
    for dt_text, dt in (("10.0MSEC", 0.01), (".0100SEC", 0.01)):
        path = _write(tmp_path, "g.AT2", "PEER NGA STRONG MOTION DATABASE RECORD\nQuake, 1/1/2000, STA, 90\n"
                      f"ACCELERATION TIME SERIES IN UNITS OF G\nNPTS=   800, DT=   {dt_text}\n" + values)
        assert read_at2(path).dt == pytest.approx(dt)
