"""``sbib damper test``: run a virtual-laboratory test on a damper model, write CSV (and a plot).

Example::

    sbib damper test --model virtual --amplitude 0.4 --frequency 0.8 --voltage 0 \\
        --out virtual.csv --plot virtual.png

Models: ``virtual`` (the virtual benchmark damper), ``spencer`` (the 1997 prototype),
``bingham`` (Spencer's 1997 fit), ``dahl`` and ``hyperbolic_tangent`` (calibrated to the virtual
damper at 0 V), and ``normalized_bouc_wen`` / ``extended_bouc_wen`` (give every parameter with
``--param NAME=VALUE``, SI units). ``--param`` also overrides any default.

``--voltage`` is required for a model whose force depends on the voltage and rejected (one-line
error) for one whose does not: the defaults of ``bingham`` (one fit at 1.5 V), ``dahl`` and
``hyperbolic_tangent`` (0 V calibrations) have constant parameters, so a voltage would be
silently ignored. Give such a model voltage laws (:mod:`damper.models.voltage_laws`) through the Python
API to make it respond (see :func:`check_voltage_effect`).
"""

from __future__ import annotations

import argparse
from dataclasses import MISSING, fields

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.atomic import output_file, output_file_of
from damper.models.registry import get_model_class
from damper.io.data import write_csv
from damper.lab.laboratory import periodic_test
from damper.lab.loops import last_cycles
from damper.lab.plots import plot_loops

__all__ = ["register", "default_model", "run_test", "responds_to_voltage", "check_voltage_effect"]

_DEFAULT_FACTORIES = {
    "virtual": ("damper.models.virtual", "VirtualBenchmarkDamper", None),
    "spencer": ("damper.models.spencer", "Spencer", "prototype_1997"),
    "bingham": ("damper.models.bingham", "Bingham", "spencer_1997"),
    "dahl": ("damper.models.dahl", "Dahl", "virtual_0V"),
    "hyperbolic_tangent": ("damper.models.hyperbolic_tangent", "HyperbolicTangent", "virtual_0V"),
}


def default_model(name: str, overrides: dict[str, float] | None = None):
    """The model ``name`` with its documented default parameters, updated by ``overrides``.

    Parameters
    ----------
    name : str
        A registered damper model name (:data:`damper.models.registry.MODELS`).
    overrides : dict[str, float] | None, optional
        Parameters to change, by name (SI); None: none.
    """
    from dataclasses import replace

    cls = get_model_class(name)
    overrides = dict(overrides or {})
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise InputError(f"--param: {name} has no parameter {', '.join(unknown)}; expected one of "
                         + ", ".join(sorted(known)))
    if name in _DEFAULT_FACTORIES:
        module, _, factory = _DEFAULT_FACTORIES[name]
        base = getattr(cls, factory)() if factory else cls()
        return replace(base, **overrides) if overrides else base
    missing = [f.name for f in fields(cls) if f.name not in overrides
               and f.default is MISSING and f.default_factory is MISSING]
    if missing:
        raise InputError(f"--model {name}: give its parameters with --param NAME=VALUE; missing "
                         + ", ".join(missing))
    return cls(**overrides)


def _param(text: str) -> tuple[str, float | tuple[float, ...]]:
    if "=" not in text:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    key, value = text.split("=", 1)
    try:
        if "," in value:  # a pair such as voltage_range=0,2.25
            return key.strip(), tuple(float(v) for v in value.split(","))
        return key.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{key}: expected a number (or numbers separated by commas, "
                                         f"e.g. voltage_range=0,2), got {value!r}") from None


def responds_to_voltage(model) -> bool:
    """Whether the force of ``model`` changes with the voltage over its ``voltage_range``.

    Measured, not read off the parameters, so that it holds for any model: one period of a
    sine (10 mm, 1 Hz, 200 Hz sampling) at each end of the range; the forces must differ.

    Parameters
    ----------
    model
        A damper model instance.
    """

    lo, hi = getattr(model, "voltage_range", (0.0, 1.0))
    forces = [periodic_test(model, 0.01, 1.0, v, cycles=1.0).force for v in (lo, hi)]
    return not np.array_equal(forces[0], forces[1])


def check_voltage_effect(model, name: str, voltage: float | None) -> float:
    """The voltage [V] to test ``model`` at, or :class:`InputError` when ``voltage`` would be ignored.

    A model whose force does not depend on the voltage (:func:`responds_to_voltage`) runs at
    the low end of its range; any other voltage is rejected (the low end itself is accepted, it
    is what runs anyway). A model that does depend on the voltage needs one.

    Parameters
    ----------
    model
        The damper model tested.
    name : str
        Its name, for the error message.
    voltage : float | None
        Voltage [V] asked for; None: the model's maximum.
    """
    responds = responds_to_voltage(model)
    low = float(getattr(model, "voltage_range", (0.0, 1.0))[0])
    if voltage is None:
        if responds:
            raise InputError(f"--model {name}: its force depends on the voltage; give --voltage V")
        return low
    if not responds and float(voltage) != low:
        raise InputError(f"--model {name}: its force does not depend on the voltage (constant "
                         f"parameters), so --voltage {voltage:g} would be ignored; leave --voltage "
                         "out, or give the model voltage laws (damper.models.voltage_laws) in Python")
    return float(voltage)


def run_test(args: argparse.Namespace) -> int:
    """Run the test described by the parsed arguments; write the CSV and the plot.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line options of the sub-command.
    """

    model = default_model(args.model, dict(args.param or []))
    voltage = check_voltage_effect(model, args.model, args.voltage)
    test = periodic_test(model, args.amplitude, args.frequency, voltage, cycles=args.cycles,
                         sample_rate=args.sample_rate, noise=args.noise, seed=args.seed,
                         waveform=args.waveform)
    write_csv(test, args.out)
    steady = last_cycles(test)
    print(f"{test.name}: {test.n_samples} samples -> {args.out}; last cycle force "
          f"{steady.force.min() / 1e3:.1f} .. {steady.force.max() / 1e3:.1f} kN")
    if args.plot:
        plot_loops(steady, args.plot, title=f"{test.name} (last cycle)")
        print(f"plot -> {args.plot}")
    return 0


def register(subparsers) -> None:
    """Add ``sbib damper test``.

    Parameters
    ----------
    subparsers
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    damper_parser = subparsers.add_parser("damper", help="damper models and virtual laboratory tests")
    damper_sub = damper_parser.add_subparsers(dest="damper_command", metavar="SUBCOMMAND")
    damper_parser.set_defaults(func=lambda args: (damper_parser.print_help(), 2)[1])
    p = damper_sub.add_parser("test", help="periodic displacement test at constant voltage",
                              description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--model", required=True, help="registered model name (e.g. virtual)")
    p.add_argument("--amplitude", type=float, required=True, help="displacement amplitude [m]")
    p.add_argument("--frequency", type=float, required=True, help="frequency [Hz]")
    p.add_argument("--voltage", type=float, default=None,
                   help="constant voltage [V]; required for a model whose force depends on it, "
                        "rejected for one whose does not (bingham, dahl, hyperbolic_tangent defaults)")
    p.add_argument("--cycles", type=float, default=5.0, help="number of periods (default 5)")
    p.add_argument("--sample-rate", type=float, default=200.0, help="samples per second [Hz] (default 200)")
    p.add_argument("--noise", type=float, default=0.0, help="relative RMS force noise (default 0)")
    p.add_argument("--seed", type=int, default=None, help="noise seed")
    p.add_argument("--waveform", choices=("sine", "triangle"), default="sine",
                   help="displacement waveform (default sine; triangle: constant-velocity strokes)")
    p.add_argument("--param", type=_param, action="append", metavar="NAME=VALUE",
                   help="model parameter in SI units (repeatable)")
    p.add_argument("--out", required=True, type=output_file_of("csv"), help="output CSV file")
    p.add_argument("--plot", default=None, type=output_file, help="output PNG with the loops of the last cycle")
    p.set_defaults(func=run_test)
