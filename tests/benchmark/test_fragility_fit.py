"""Fragility: the lognormal maximum-likelihood fit, exceedance counts and the plot."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import ndtr

from benchmark.applications.ensemble import EnsembleResults
from benchmark.foundation.errors import InputError
from benchmark.applications.fragility import (STANDARD_GRAVITY, exceedance_counts, fit_lognormal, fragility_config,
                                 fragility_curves, plot_fragility)


def test_fit_recovers_known_curve_from_many_binomial_draws():
    rng = np.random.default_rng(5)
    theta, beta = 4.0, 0.35
    a = np.linspace(1.0, 9.0, 12)
    n = np.full(a.size, 4000)
    z = rng.binomial(n, ndtr(np.log(a / theta) / beta))
    fit = fit_lognormal(a, z, n)
    assert fit.fitted
    assert fit.median == pytest.approx(theta, rel=0.02)
    assert fit.beta == pytest.approx(beta, rel=0.05)
    # the optimum beats nearby parameter sets
    from benchmark.applications.fragility import _log_likelihood
    for dt, db in ((0.05, 0), (-0.05, 0), (0, 0.05), (0, -0.05)):
        assert _log_likelihood(math.log(fit.median) + dt, math.log(fit.beta) + db, np.log(a), z, n) < fit.log_likelihood


def test_fit_on_exact_probabilities_is_exact():
    # with counts proportional to exact probabilities the likelihood peaks at the true values
    theta, beta = 2.5, 0.5
    a = np.array([0.5, 1, 1.5, 2, 2.5, 3, 4, 5, 6.0])
    n = np.full(a.size, 10 ** 6)
    z = np.round(n * ndtr(np.log(a / theta) / beta))
    fit = fit_lognormal(a, z, n)
    assert fit.median == pytest.approx(theta, rel=1e-3) and fit.beta == pytest.approx(beta, rel=1e-3)
    assert np.allclose(fit.probability(a), z / n, atol=1e-3)


def test_fit_reports_unidentifiable_data():
    assert not fit_lognormal([1, 2, 3], [0, 0, 0], [5, 5, 5]).fitted
    assert not fit_lognormal([1, 2, 3], [5, 5, 5], [5, 5, 5]).fitted
    sep = fit_lognormal([1, 2, 3, 4], [0, 0, 5, 5], [5, 5, 5, 5])
    assert not sep.fitted and "not identified" in sep.message
    assert 2 < sep.median < 3
    with pytest.raises(InputError, match="n_exceed <= n_total"):
        fit_lognormal([1, 2], [3, 1], [2, 2])
    with pytest.raises(InputError, match="> 0"):
        fit_lognormal([0, 2], [0, 1], [2, 2])


def _fake_results() -> EnsembleResults:
    # two controllers, 3 PGA levels, 4 runs each; controller B halves the displacement
    rng = np.random.default_rng(0)
    pga = np.repeat([2.0, 4.0, 6.0], 4)
    disp_a = 0.1 * pga * np.exp(0.3 * rng.standard_normal(pga.size))
    cases = {"controller": np.array(["A"] * 12 + ["B"] * 12), "status": np.array(["ok"] * 23 + ["failed"]),
             "pga": np.concatenate([pga, pga])}
    results = {"peak_base_displacement": np.concatenate([disp_a, 0.5 * disp_a]),
               "vector": np.zeros((24, 2))}
    return EnsembleResults(cases=cases, parameters={}, results=results), disp_a


def test_exceedance_counts_and_curves():
    res, disp_a = _fake_results()
    levels, z, n = exceedance_counts(res, "A", limit=0.4)
    assert levels.tolist() == [2.0, 4.0, 6.0] and n.tolist() == [4, 4, 4]
    assert z.tolist() == [int(np.sum(disp_a[i * 4:(i + 1) * 4] > 0.4)) for i in range(3)]
    _, zb, nb = exceedance_counts(res, "B", limit=0.4)
    assert nb.tolist() == [4, 4, 3]  # the failed run is not counted
    assert np.all(zb <= z)
    curves = fragility_curves(res, limit=0.4)
    assert list(curves) == ["A", "B"]
    assert curves["B"].n_failed.tolist() == [0, 0, 1] and curves["A"].n_failed.tolist() == [0, 0, 0]
    assert curves["B"].as_dict()["n_failed"] == [0, 0, 1]
    with pytest.raises(InputError, match="metric 'nope'"):
        exceedance_counts(res, "A", metric="nope")
    with pytest.raises(InputError, match="not a scalar"):
        exceedance_counts(res, "A", metric="vector")
    with pytest.raises(InputError, match="controller 'C'"):
        exceedance_counts(res, "C")


def test_plot_is_written(tmp_path):
    res, _ = _fake_results()
    path = plot_fragility(fragility_curves(res, limit=0.4), tmp_path / "f.png", limit=0.4)
    assert path.is_file() and path.stat().st_size > 10_000


def test_fragility_config_shares_motions_between_controllers():
    cfg = fragility_config(controllers=("passive-off", "clipped-optimal"), templates=("kobe",), realisations=3,
                           pga_g=(0.2, 0.4))
    cases = cfg.cases()
    assert len(cases) == 3 * 2 * 2
    assert {round(c.pga / STANDARD_GRAVITY, 9) for c in cases} == {0.2, 0.4}
    seeds = {}
    for c in cases:
        seeds.setdefault(c.realisation, set()).add(c.motion_seed)
    assert all(len(s) == 1 for s in seeds.values()) and len(seeds) == 3


@pytest.mark.slow
def test_run_fragility_end_to_end(tmp_path, shared_dir):
    from benchmark.applications.fragility import run_fragility

    report = run_fragility(tmp_path, limit=0.05, jobs=1, progress=False, controllers=("passive-off", "passive-on"),
                           templates=("kobe",), realisations=2, pga_g=(0.1, 0.4))
    assert (tmp_path / "fragility.png").is_file() and (tmp_path / "fragility.json").is_file()
    curves = {c["controller"]: c for c in report["curves"]}
    assert set(curves) == {"passive-off", "passive-on"}
    for c in curves.values():
        assert c["n_total"] == [2, 2]
        assert c["n_exceed"][0] <= c["n_exceed"][1]  # stronger shaking, more exceedance


@pytest.mark.parametrize("args, words", [(["--limit", "-1"], "fragility limit must be > 0"),
                                         (["--jobs", "0"], "--jobs 0: expected at least 1 process")])
def test_bad_fragility_options_end_in_one_line(tmp_path, capsys, args, words):
    """A probe: --limit -1 and --jobs 0 ended in a 12-line traceback (status 1)."""
    from benchmark.applications.fragility import main
    assert main(["--quick", "--out", str(tmp_path / "f"), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err
