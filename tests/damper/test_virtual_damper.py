"""The virtual benchmark damper: calibration figures (DOMAIN.md §3) measured from laboratory
loops, the kernel against solve_ivp, field dynamics, and the laboratory protocols."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from benchmark.foundation.errors import InputError, ParameterError
from damper import simulate
from damper.lab.laboratory import general_test, periodic_test
from damper.lab.loops import dissipated_energy, last_cycles, midline_slope, plastic_branch_fit
from damper.models.spencer import Spencer
from damper.models.virtual import VirtualBenchmarkDamper


@pytest.fixture(scope="module")
def device():
    return VirtualBenchmarkDamper()


@pytest.fixture(scope="module")
def large_loop(device):
    """0 V, ±0.4 m at 0.8 Hz (±2 m/s), the seed's Fig. 1-3 test; last of three cycles."""
    return last_cycles(periodic_test(device, 0.4, 0.8, 0.0, cycles=3, sample_rate=400))


def test_average_inclination_is_207_kN_per_m(large_loop):
    assert midline_slope(large_loop) == pytest.approx(207e3, rel=0.05)


def test_force_after_removing_elastic_part_spans_250_kN_at_2_m_per_s(large_loop):
    kappa_x = midline_slope(large_loop)
    reduced = large_loop.force - kappa_x * large_loop.displacement
    assert np.max(np.abs(large_loop.velocity)) == pytest.approx(2.0, rel=0.02)
    assert reduced[np.argmax(large_loop.velocity)] == pytest.approx(250e3, rel=0.08)
    assert reduced[np.argmin(large_loop.velocity)] == pytest.approx(-250e3, rel=0.08)


def test_plastic_branch_is_wider_than_a_bouc_wen_loop(large_loop):
    """At the same velocity on the plastic branch, the accelerating (x < 0) and decelerating
    (x > 0) halves differ by about 2 kappa_x x; removing kappa_x x closes the branch (Fig. 1, 3)."""
    loop = large_loop
    kappa_x = midline_slope(loop)
    loading = loop.velocity > 0
    widths, widths_reduced = [], []
    for target in (0.8, 1.2, 1.6):
        before = loading & (loop.displacement < 0)
        after = loading & (loop.displacement > 0)
        i = np.flatnonzero(before)[np.argmin(np.abs(loop.velocity[before] - target))]
        j = np.flatnonzero(after)[np.argmin(np.abs(loop.velocity[after] - target))]
        widths.append(loop.force[j] - loop.force[i])
        reduced = loop.force - kappa_x * loop.displacement
        widths_reduced.append(abs(reduced[j] - reduced[i]))
    assert min(widths) > 60e3
    assert max(widths_reduced) < 0.2 * min(widths)


def test_small_amplitude_test_reaches_about_80_kN(device):
    """Fig. 6: ±0.03 m at 0 V over 10 s (1 Hz) -> about ±80 kN."""
    test = periodic_test(device, 0.03, 1.0, 0.0, cycles=10, sample_rate=200)
    assert test.time[-1] == pytest.approx(10.0)
    steady = last_cycles(test, cycles=2)
    assert steady.force.max() == pytest.approx(80e3, rel=0.1)
    assert steady.force.min() == pytest.approx(-80e3, rel=0.1)


def test_dry_friction_grows_from_50_to_1000_kN(device, large_loop):
    kappa_x = midline_slope(large_loop)
    friction = {}
    for v in (0.0, 0.5, 1.0):
        loop = last_cycles(periodic_test(device, 0.4, 0.8, v, cycles=3, sample_rate=200))
        friction[v] = plastic_branch_fit(loop, kappa_x)[1]
    assert friction[0.0] == pytest.approx(50e3, rel=0.2)
    assert friction[1.0] == pytest.approx(1000e3, rel=0.1)
    assert friction[0.0] < friction[0.5] < friction[1.0]


@pytest.mark.parametrize("model", [VirtualBenchmarkDamper(), Spencer.prototype_1997()],
                         ids=["virtual", "spencer"])
def test_kernel_matches_solve_ivp_with_voltage_step(model):
    amplitude, frequency, max_step = ((0.1, 1.0, 1e-3) if model.name == "virtual"
                                      else (0.01, 2.5, 2e-4))
    omega = 2 * np.pi * frequency
    v_high = model.voltage_range[1] * 0.8
    t = np.arange(0.0, 0.6 + 1e-12, 0.002)
    v_of_t = np.where(t >= 0.3, v_high, 0.0)

    def rhs(tt, s):
        return model.rates(s, amplitude * np.sin(omega * tt), amplitude * omega * np.cos(omega * tt),
                           v_high if tt >= 0.3 else 0.0)

    sol = solve_ivp(rhs, (0, t[-1]), model.initial_state(), method="Radau", t_eval=t, rtol=1e-9,
                    atol=1e-12, max_step=max_step)
    assert sol.success
    x, xd = amplitude * np.sin(omega * t), amplitude * omega * np.cos(omega * t)
    reference = np.array([model.force(sol.y[:, k], x[k], xd[k]) for k in range(t.size)])
    response = simulate(model, t, x, xd, v=v_of_t)
    assert np.max(np.abs(response.force - reference)) < 2e-4 * np.max(np.abs(reference))


def test_field_follows_first_order_dynamics(device):
    t = np.arange(0.0, 0.5 + 1e-12, 0.001)
    response = simulate(device, t, 0.05 * t, v=np.where(t >= 0.1, 1.0, 0.0))
    u = response.states[:, 2]
    after = t >= 0.1
    expected = 1.0 - np.exp(-device.eta * (t[after] - 0.1))
    # voltage held from a sample to the next: the sample at t = 0.1 starts the rise
    assert np.allclose(u[after][1:], 1.0 - np.exp(-device.eta * (t[after][1:] - 0.1)), atol=1e-12)
    assert u[~after].max() == 0.0 and expected[-1] > 0.99
    # the force lags the command: one time constant after the step it is part-way up
    k = np.searchsorted(t, 0.1 + 1 / device.eta)
    f0, f1 = response.force[np.searchsorted(t, 0.1)], response.force[-1]
    assert f0 + 0.3 * (f1 - f0) < response.force[k] < f0 + 0.9 * (f1 - f0)


def test_laboratory_noise_is_seeded_and_relative(device):
    clean = periodic_test(device, 0.05, 1.0, 0.2, cycles=2)
    a = periodic_test(device, 0.05, 1.0, 0.2, cycles=2, noise=0.05, seed=7)
    b = periodic_test(device, 0.05, 1.0, 0.2, cycles=2, noise=0.05, seed=7)
    assert np.array_equal(a.force, b.force)
    rel = np.sqrt(np.mean((a.force - clean.force) ** 2) / np.mean(clean.force ** 2))
    assert rel == pytest.approx(0.05, rel=0.2)
    assert np.array_equal(a.displacement, clean.displacement)


def test_triangle_wave_and_general_test(device):
    tri = periodic_test("virtual", 0.02, 0.5, 0.0, cycles=2, sample_rate=400, waveform="triangle")
    assert tri.displacement.max() == pytest.approx(0.02, rel=1e-9)
    speeds = np.abs(tri.velocity[np.abs(tri.velocity) > 0])
    assert np.allclose(speeds, 4 * 0.02 * 0.5)
    # the general protocol with the same motion gives the same force (velocity from x)
    gen = general_test(device, tri.time, tri.displacement, 0.0, xdot=tri.velocity)
    assert np.allclose(gen.force, tri.force)
    assert dissipated_energy(last_cycles(tri)) > 0


@pytest.mark.parametrize("kwargs, match", [
    (dict(voltage=1.5), "voltage"), (dict(voltage=-0.1), "voltage"),
    (dict(amplitude=0.0), "amplitude"), (dict(frequency=-1.0), "frequency"),
    (dict(sample_rate=5.0), "sample_rate"), (dict(waveform="square"), "waveform"),
    (dict(noise=-0.1), "noise"),
])
def test_laboratory_rejects_bad_protocols(device, kwargs, match):
    args = dict(amplitude=0.01, frequency=1.0, voltage=0.0)
    args.update(kwargs)
    with pytest.raises(InputError, match=match):
        periodic_test(device, **args)


def test_bad_virtual_parameters():
    with pytest.raises(ParameterError, match="sigma"):
        VirtualBenchmarkDamper(sigma=0.3)
    with pytest.raises(ParameterError, match="eta"):
        VirtualBenchmarkDamper(eta=0.0)
    with pytest.raises(ParameterError, match="gamma >= beta"):
        Spencer.prototype_1997(gamma=1.0)


def test_identification_does_not_import_the_virtual_damper():
    """Identification reaches the virtual damper only through damper.lab.laboratory."""
    package = Path(__file__).resolve().parents[2] / "damper"
    for path in sorted(package.glob("*ident*.py")) + sorted(package.glob("identification/*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""] + [a.name for a in node.names]
            assert not any("virtual" in n.lower() for n in names), f"{path.name} imports {names}"


def test_spencer_type_kernel_converges_as_tolerance_tightens():
    t = np.arange(0.0, 1.0 + 1e-12, 0.005)
    x = 0.2 * np.sin(2 * np.pi * t)
    v = np.where(t >= 0.4, 1.0, 0.0)
    reference = simulate(VirtualBenchmarkDamper(substep_tolerance=0.002), t, x, v=v).force
    errors = [np.max(np.abs(simulate(VirtualBenchmarkDamper(substep_tolerance=tol), t, x, v=v).force
                            - reference)) / np.max(np.abs(reference)) for tol in (0.8, 0.2, 0.05)]
    assert errors[0] > errors[1] > errors[2] and errors[2] < 1e-4
