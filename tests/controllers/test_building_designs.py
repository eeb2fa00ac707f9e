"""Model-based controllers designed on the benchmark building's linear model (needs shared data)."""

from __future__ import annotations

import numpy as np
import pytest

import damper
from benchmark.foundation.errors import InputError
from benchmark.simulator.control import control_context, design_model
from controllers.base import ControlContext
from controllers.clipped_optimal import ClippedOptimal, LQGWeights
from controllers.compiled import run_compiled
from controllers.lqg import simulate_linear
from controllers.lyapunov import Lyapunov
from controllers.modulated import ModulatedClippedOptimal
from controllers.plant import building_plant
from controllers.registry import controller_names, get_controller
from controllers.skyhook import Skyhook


@pytest.fixture(scope="module")
def building(shared_dir):
    from benchmark.simulator.building import Building

    # A 1000 kN-class extended Bouc-Wen damper (DOMAIN.md §3 orders of magnitude).
    model = damper.ExtendedBoucWen(kappa_x=207e3, kappa_xdot=damper.Polynomial((100e3, 200e3)),
                                   kappa_w=damper.Polynomial((50e3, 950e3)), rho=40.0, sigma=1.0, n=1.5)
    return Building.default(damper_model=model)


@pytest.fixture(scope="module")
def context(building):
    return control_context(building, control_step=0.005)


@pytest.fixture(scope="module")
def clipped(context):
    c = ClippedOptimal(check_fit=True)
    c.reset(context)
    return c


def test_lqg_riccati_residuals_and_stability(clipped):
    d = clipped.design
    assert d.riccati_residuals["lqr"] < 1e-8
    assert d.riccati_residuals["kalman"] < 1e-8
    assert np.all(d.lqr["closed_loop_poles"].real < 0)
    assert np.all(np.abs(d.kalman["poles"]) < 1)
    report = d.report()
    assert "LQR closed-loop poles" in report and "estimator fit" in report


def test_estimator_tracks_full_model_noise_free(clipped):
    fit = clipped.design.fit
    for axis in "xyθ":
        assert fit[f"base displacement {axis}"] > 97.0, fit
        assert fit[f"base velocity {axis}"] > 85.0, fit


def test_compiled_estimate_matches_linear_model_base_displacement(building, clipped):
    """Closed chain: full linear model → measurement vector → compiled kernel; the controller's
    state x̂[k|k-1] reproduces the base displacement of the full model."""
    plant = building_plant(design_model(building))
    rng = np.random.default_rng(2)
    n = 3000
    ground = np.column_stack([np.convolve(rng.standard_normal(n), np.ones(8) / 8, "same") for _ in range(2)]) * 2
    x, y = simulate_linear(plant, 0.005, ground)
    _, desired, states = run_compiled(clipped.compiled(), y)
    p = clipped.design.reduced.plant
    est = states[:-1] @ p.C[27:29].T
    err = np.linalg.norm(est[500:] - y[500:, 27:29]) / np.linalg.norm(y[500:, 27:29])
    assert err < 0.05
    assert np.all(np.isfinite(desired))


def test_all_registered_controllers_build_and_step(context):
    y = np.zeros(context.n_measurements)
    y[27] = 0.2          # base displaced 0.2 m in x
    y[-context.n_devices:] = 1e4
    for name in controller_names():
        controller = get_controller(name)
        if controller is None:
            continue
        controller.reset(context)
        v = controller.step(y)
        assert v.shape == (context.n_devices,)
        assert np.all((v >= 0) & (v <= context.voltage_max))


def test_modulated_and_lyapunov_share_the_estimator(context):
    m, ly = ModulatedClippedOptimal(), Lyapunov()
    m.reset(context)
    ly.reset(context)
    np.testing.assert_allclose(m.compiled().Ac, ly.compiled().Ac)
    assert ly.lyapunov_residual < 1e-8
    assert np.all(m.compiled().law_params > 1e5)


def test_skyhook_integrates_base_acceleration(context):
    sky = Skyhook(damping=1e6, highpass_frequency=1e-6)
    sky.reset(context)
    n = 200
    y = np.zeros((n, context.n_measurements))
    y[:, 0] = 1.0  # 1 m/s² absolute base acceleration in x for 1 s
    _, desired, _ = run_compiled(sky.compiled(), y, device_force=np.full((n, context.n_devices), 1.0))
    x_devices = context.design_model.device_directions == 0
    np.testing.assert_allclose(desired[-1, x_devices], 1e6 * 1.0, rtol=1e-3)
    np.testing.assert_allclose(desired[-1, ~x_devices], 0.0, atol=1e-6)


def test_model_based_controller_without_design_model_is_a_clear_error():
    ctx = ControlContext(n_devices=2, control_step=0.005, voltage_max=1.0)
    with pytest.raises(InputError, match="no design model"):
        ClippedOptimal(weights=LQGWeights(force_scale=1e5)).reset(ctx)


def test_unknown_controller_name():
    with pytest.raises(InputError, match="expected one of"):
        get_controller("fuzzy")


def test_lqg_design_is_shared_between_controllers_on_one_building_only():
    """Per-run controller objects reuse the design; other weights or buildings get their own."""
    from dataclasses import replace

    from benchmark.simulator.building import Building
    from controllers.base import ControlContext
    from controllers.clipped_optimal import ClippedOptimal

    building = Building.default()
    context = control_context(building, 0.005)
    first, second = ClippedOptimal(), ClippedOptimal()
    first.build(context)
    second.build(context)
    assert second.design is first.design
    other = ClippedOptimal(weights=replace(first.weights, r_force=first.weights.r_force * 10))
    other.build(context)
    assert other.design is not first.design
    elsewhere = ClippedOptimal()
    elsewhere.build(control_context(Building.default(), 0.005))
    assert elsewhere.design is not first.design
