"""What the package writes for people names its units and cites only what a reader can open:
every CSV header names the unit of each numeric column, every ``*.md`` a JSON key cites exists
in the repository, and the README's examples write under one ignored folder."""

from __future__ import annotations

import csv
import re
import subprocess
from pathlib import Path

import numpy as np

from benchmark.applications.cli import main
from benchmark.applications.identification_study import write_parameters_csv
from benchmark.simulator.criteria import key_json

ROOT = Path(__file__).resolve().parents[2]
UNIT = re.compile(r"^.+ \[[^\]]+\]$")


def _header_and_first_row(path: Path) -> tuple[list[str], list[str]]:
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if not ln.startswith("#")]
    rows = list(csv.reader(lines))
    return rows[0], rows[1]


def _numeric_columns_without_unit(path: Path) -> list[str]:
    header, row = _header_and_first_row(path)
    missing = []
    for name, value in zip(header, row):
        try:
            float(value)
        except ValueError:
            continue  # a text column (a model's name) has no unit
        if not UNIT.match(name.strip()):
            missing.append(name)
    return missing


def test_damper_test_csv_names_its_units(tmp_path):
    out = tmp_path / "virtual.csv"
    assert main(["damper", "test", "--model", "virtual", "--amplitude", "0.01", "--frequency", "1",
                 "--voltage", "0.5", "--cycles", "1", "--out", str(out)]) == 0
    header, _ = _header_and_first_row(out)
    assert header == ["time [s]", "displacement [m]", "force [N]", "velocity [m/s]", "voltage [V]"]
    from damper.io.data import read_csv  # the reader takes the units back

    test = read_csv(out)
    assert test.voltage is not None and np.allclose(test.voltage, 0.5)


def test_parameters_csv_names_its_units(tmp_path):
    row = {"model": "extended", "voltage": 0.5, "kappa_x_mode": "large-loop", "kappa_x": 2.0e5,
           "kappa_xdot": 1.0e5, "kappa_w": 5.0e4, "rho": 100.0, "sigma": 0.5, "n": 1.0,
           "kappa_x_std": 1.0, "rho_std": 0.1, "rel_rms_error": 0.01, "peak_error": 0.02,
           "energy_error": 0.03, "rho_stroke": 4.0}
    path = write_parameters_csv([row], tmp_path / "parameters.csv")
    assert not _numeric_columns_without_unit(path)
    header, _ = _header_and_first_row(path)
    assert "kappa_x [N/m]" in header and "kappa_x_std [N/m]" in header and "voltage [V]" in header


def test_cited_documents_exist():
    text = repr(key_json())
    cited = set(re.findall(r"[\w./-]+\.md", text))
    missing = [c for c in cited if not (ROOT / c).is_file() and not list(ROOT.glob(f"**/{c}"))]
    assert not missing, f"JSON cites documents that are not in the repository: {missing}"


def _readme_output_paths() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    paths = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for line in block.replace("\\\n", " ").splitlines():
            if not line.strip().startswith("sbib "):
                continue
            paths += re.findall(r"--(?:out|plot)[ =](\S+)", line)
    return paths


def test_readme_examples_write_under_one_ignored_folder():
    paths = _readme_output_paths()
    assert paths, "no sbib example with --out in the README"
    roots = {Path(p).parts[0] for p in paths}
    assert len(roots) == 1, f"README examples write into several places: {sorted(roots)}"
    ignored = subprocess.run(["git", "check-ignore", "--no-index", *paths], cwd=ROOT,
                             capture_output=True, text=True).stdout.split()
    assert sorted(set(ignored)) == sorted(set(paths)), \
        f"not ignored by .gitignore: {sorted(set(paths) - set(ignored))}"


def test_readme_ensemble_count_is_the_example_config():
    from benchmark.applications.ensemble import EnsembleConfig

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    stated = re.findall(r"example ensemble runs (\d+) simulations", text)
    assert stated, "the README no longer states the example ensemble's size"
    n = len(EnsembleConfig.from_toml(ROOT / "examples" / "ensemble.toml").cases())
    assert all(int(s) == n for s in stated), f"README says {stated}, the example runs {n}"
