"""The header-cell rule shared by the readers of damper tests and force histories."""

import pytest

from benchmark.foundation.file_units import column_name_unit


@pytest.mark.parametrize("cell, expected", [
    ("disp [mm]", ("displacement", "mm")),
    ("Disp (mm)", ("displacement", "mm")),
    ('"load"', ("force", None)),
    ("  Velocity [ mm / s ] ", ("velocity", "mm / s")),
    ("time []", ("time", None)),
    ("voltage", ("voltage", None)),
])
def test_header_cells_split_into_name_and_unit(cell, expected):
    assert column_name_unit(cell) == expected


@pytest.mark.parametrize("cell", ["force [N", "2nd force", "force [N] extra", ""])
def test_cells_that_are_not_a_name_with_a_unit(cell):
    assert column_name_unit(cell) is None
