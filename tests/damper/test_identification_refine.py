"""Identification end to end on a device with known parameters: recovery within 1 % / 5 %."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.models.bouc_wen import ExtendedBoucWen
from damper.identification.identify import identify, identify_arrays
from damper.identification.metrics import (dissipated_energy, energy_error, force_errors,
                                           peak_error, relative_rms_error, spencer_errors)
from damper.models.response import simulate

# A device of the benchmark's scale (DOMAIN.md §3: kappa_x ~ 207 kN/m, kappa_xdot ~ 100 kN s/m).
TRUE = dict(kappa_x=2.07e5, kappa_xdot=1.0e5, kappa_w=1.2e5, rho=120.0, sigma=0.9, n=1.4)


def periodic_data(p=TRUE, amplitude=0.1, frequency=0.5, cycles=6, dt=2e-3, noise=0.0, seed=0):
    t = np.arange(0.0, cycles / frequency + dt / 2, dt)
    om = 2 * np.pi * frequency
    x = amplitude * np.sin(om * t)
    xd = amplitude * om * np.cos(om * t)
    force = simulate(ExtendedBoucWen(**p), t, x, xd).force
    if noise:
        force = force + noise * np.std(force) * np.random.default_rng(seed).standard_normal(t.size)
    return t, x, xd, force


def _relative(params: dict) -> dict:
    return {k: params[k] / TRUE[k] - 1.0 for k in TRUE}


def test_noise_free_extended_device_is_recovered_within_one_percent():
    t, x, xd, force = periodic_data()
    ident = identify_arrays(t, x, force, xd, model="extended")
    rel = _relative(ident.parameters)
    assert max(abs(v) for v in rel.values()) < 0.01, rel
    assert ident.errors["rel_rms_error"] < 1e-4
    assert ident.fit.success


def test_two_percent_noise_recovers_within_five_percent_and_reports_uncertainty():
    t, x, xd, force = periodic_data(noise=0.02, seed=3)
    ident = identify_arrays(t, x, force, xd, model="extended", n_bootstrap=8, seed=1)
    rel = _relative(ident.parameters)
    assert max(abs(v) for v in rel.values()) < 0.05, rel
    # The residual is the noise: its relative RMS is about 2 % of std/rms.
    assert 0.01 < ident.errors["rel_rms_error"] < 0.03
    for k in TRUE:
        assert ident.fit.standard_error[k] > 0.0
        assert ident.fit.bootstrap_std[k] > 0.0
        # The truth lies within a few standard errors (bootstrap spread) of the estimate.
        spread = max(ident.fit.standard_error[k], ident.fit.bootstrap_std[k])
        assert abs(ident.parameters[k] - TRUE[k]) < 6 * spread + 1e-3 * TRUE[k], k


def test_normalized_model_cannot_fit_an_inclined_loop():
    t, x, xd, force = periodic_data()
    ext = identify_arrays(t, x, force, xd, model="extended")
    nor = identify_arrays(t, x, force, xd, model="normalized")
    assert nor.parameters["kappa_x"] == 0.0
    assert nor.errors["rel_rms_error"] > 20 * ext.errors["rel_rms_error"]
    assert nor.errors["rel_rms_error"] > 0.01


def test_identify_takes_a_damper_test_and_rejects_varying_voltage():
    from damper.io.data import DamperTest
    t, x, xd, force = periodic_data(cycles=4)
    test = DamperTest(time=t, displacement=x, velocity=xd, force=force, voltage=np.full(t.size, 0.3),
                      name="unit")
    ident = identify(test)
    assert ident.level == pytest.approx(0.3) and ident.level_unit == "V"
    assert ident.summary()["parameters"]["rho"] == pytest.approx(TRUE["rho"], rel=0.01)
    ramp = DamperTest(time=t, displacement=x, velocity=xd, force=force, voltage=np.linspace(0, 1, t.size),
                      name="ramp")
    with pytest.raises(InputError, match="varies over the test"):
        identify(ramp)


def test_amplitude_ramps_are_skipped_and_the_plateau_used():
    # Like the UTFSM files: the amplitude ramps up over 1.5 cycles and down at the end.
    dt, f = 2e-3, 0.5
    t = np.arange(0, 8 / f, dt)
    envelope = np.clip(np.minimum(t / 3.0, (t[-1] - t) / 3.0), 0, 1)
    x = 0.1 * envelope * np.sin(2 * np.pi * f * t)
    xd = np.gradient(x, t)
    force = simulate(ExtendedBoucWen(**TRUE), t, x, xd).force
    ident = identify_arrays(t, x, force, xd)
    strokes = [x[c.peak] - x[c.start] for c in ident.cycles]
    assert min(strokes) > 0.19
    assert max(abs(v) for v in _relative(ident.parameters).values()) < 0.01


def test_metrics_on_known_histories():
    t = np.linspace(0, 2, 2001)
    x = np.sin(2 * np.pi * t)
    v = 2 * np.pi * np.cos(2 * np.pi * t)
    f = np.cos(2 * np.pi * t)  # F ~ velocity: a viscous loop
    g = 1.1 * f
    assert relative_rms_error(f, g) == pytest.approx(0.1)
    assert peak_error(f, g) == pytest.approx(0.1)
    assert energy_error(f, g, x) == pytest.approx(0.1, rel=1e-6)
    # Two cycles of F = cos, x = sin: each dissipates the ellipse area pi.
    assert dissipated_energy(f, x) == pytest.approx(2 * np.pi, rel=1e-4)
    e = spencer_errors(t, f, g, x, v)
    for name in ("E_t", "E_x", "E_xdot"):
        assert e[name] == pytest.approx(0.01, rel=1e-3)  # (0.1 F)^2 over F's variance, any weight
    assert set(force_errors(t, f, g, x, v)) == {"rel_rms_error", "peak_error", "energy_error",
                                                "E_t", "E_x", "E_xdot"}
    with pytest.raises(InputError):
        relative_rms_error(f, g[:-1])


def test_fixed_kappa_x_is_held_and_the_rest_recovered():
    """The seed's method: kappa_x given (read once elsewhere), the rest identified on F - kappa_x x."""
    t, x, xd, force = periodic_data()
    ident = identify_arrays(t, x, force, xd, model="extended", kappa_x=TRUE["kappa_x"])
    assert ident.parameters["kappa_x"] == TRUE["kappa_x"]
    assert "kappa_x" not in ident.fit.free and ident.fit.standard_error["kappa_x"] == 0.0
    assert ident.closed_form.kappa_x_method == "fixed"
    assert max(abs(v) for v in _relative(ident.parameters).values()) < 0.01
    # A wrong kappa_x stays wrong (it is not re-fitted) and the fit pays for it.
    off = identify_arrays(t, x, force, xd, model="extended", kappa_x=0.7 * TRUE["kappa_x"])
    assert off.parameters["kappa_x"] == pytest.approx(0.7 * TRUE["kappa_x"])
    assert off.errors["rel_rms_error"] > 100 * ident.errors["rel_rms_error"]
    with pytest.raises(InputError, match="extended model only"):
        identify_arrays(t, x, force, xd, model="normalized", kappa_x=1e5)
    with pytest.raises(InputError, match="kappa_x"):
        identify_arrays(t, x, force, xd, model="extended", kappa_x=-1.0)


def test_refine_shared_recovers_one_kappa_x_common_to_several_tests():
    from damper.identification.refine import refine, refine_shared
    devices = [TRUE, dict(TRUE, kappa_xdot=2.0e5, kappa_w=4.0e5, rho=100.0, sigma=1.5, n=1.8)]
    tests, starts = [], []
    for p in devices:
        t, x, xd, force = periodic_data(p)
        ident = identify_arrays(t, x, force, xd, model="extended", kappa_x=1.6e5)  # a biased start
        tests.append((t, x, xd, force, ident.cycles))
        starts.append(ident.parameters)
    shared = refine_shared(tests, starts, shared="kappa_x")
    assert shared.start == pytest.approx(1.6e5)
    assert shared.value == pytest.approx(TRUE["kappa_x"], rel=0.01)
    for p, fitted, err in zip(devices, shared.parameters, shared.rel_rms_errors):
        assert fitted["kappa_x"] == shared.value
        assert fitted["kappa_w"] == pytest.approx(p["kappa_w"], rel=0.01)
        assert err < 1e-3
    assert shared.standard_error >= 0.0
    with pytest.raises(InputError):
        refine_shared(tests, starts[:1])
    with pytest.raises(InputError, match="fixed"):
        refine(*tests[0], starts[0], model="normalized", fixed={"kappa_x": 1.0})


@pytest.mark.parametrize("model", ["normalized", "extended"])
def test_refine_reads_the_kappa_columns_off_the_held_w_history(model):
    """A point that differs from the last simulated one only in κ_x, κ_ẋ, κ_w is read off its w
    history (the Jacobian's κ columns): equal to a simulation to rounding; ρ, σ or n simulate."""
    from damper.identification.refine import _Problem, free_parameters, make_model
    t = np.linspace(0.0, 4.0, 1601)
    x, xd = 0.02 * np.sin(2 * np.pi * t), 0.04 * np.pi * np.cos(2 * np.pi * t)
    start = {"kappa_x": 2e4, "kappa_xdot": 3e4, "kappa_w": 8e4, "rho": 150.0, "sigma": 1.2, "n": 1.5}
    force = simulate(make_model(model, start), t, x, xd, 0.0).force
    problem = _Problem(model, t, x, xd, force, np.arange(400, 1601), start, substep_tolerance=0.25)
    calls = {"n": 0}
    import sys
    refine_module = sys.modules["damper.identification.refine"]  # the package's `refine` is the function
    plain = refine_module.simulate

    def counted(*args, **kwargs):
        calls["n"] += 1
        return plain(*args, **kwargs)

    patch = pytest.MonkeyPatch()
    patch.setattr(refine_module, "simulate", counted)
    try:
        q = np.ones(len(problem.free))
        problem.simulate(q)
        for j, name in enumerate(problem.free):
            step = q.copy()
            step[j] *= 1.0 + 1e-5
            got = problem.simulate(step)
            want = plain(make_model(model, problem.parameters(step), substep_tolerance=0.25), t, x, xd, 0.0).force
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(np.abs(want)), err_msg=name)
            problem.simulate(q)
    finally:
        patch.undo()
    kappas = sum(name.startswith("kappa") for name in free_parameters(model))
    shapes = len(problem.free) - kappas
    assert calls["n"] == 1 + 2 * shapes  # the centre, then each shape column and the centre again
    assert problem.nsim == 1 + 2 * len(problem.free)  # every evaluation still counts as one
