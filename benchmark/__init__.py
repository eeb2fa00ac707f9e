"""Smart base-isolated benchmark building (Narasimhan et al. 2006) with MR dampers.

The façade of the project, the way python-control's is (``import control as ct; ct.ss(...)``)::

    import benchmark as sb

    record = sb.load_benchmark_record("kobe", "FN-x")      # m/s², dt = 0.005 s
    building = sb.Building.default()                       # friction-lrb isolation, 16 MR dampers
    reference = sb.simulate(building, record)              # the uncontrolled building
    result = sb.simulate(building, record, controller="clipped-optimal")
    J = sb.evaluate(result, reference)                     # {"J1": ..., ..., "J9": ...}
    run = sb.run_case(sb.Case(record="kobe", controller="skyhook"))

Every name is loaded on first use (:mod:`benchmark.foundation.facade`), so importing
``benchmark`` (which ``records`` and ``damper`` do, for :mod:`benchmark.foundation`) loads neither
the simulator nor its compiled kernels.
"""

from benchmark.foundation.facade import lazy_exports

__version__ = "0.1.0"

#: Public name -> the module that defines it.
EXPORTS = {
    "Building": "benchmark.simulator.building",
    "simulate": "benchmark.simulator.simulation",
    "SimulationResult": "benchmark.simulator.simulation",
    "Case": "benchmark.simulator.case",
    "CaseResult": "benchmark.simulator.case",
    "run_case": "benchmark.simulator.case",
    "evaluate": "benchmark.simulator.evaluation",
    "J_DESCRIPTIONS": "benchmark.simulator.evaluation",
    "Peaks": "benchmark.simulator.peaks",
    "write_result": "benchmark.simulator.results",
    "read_result": "benchmark.simulator.results",
    "simulate_oracle": "benchmark.simulator.oracle",
    "compare": "benchmark.applications.comparison",
    "load_benchmark_record": "records",
    "load_record": "records",
    "Record": "records",
}

__all__ = ["__version__", *EXPORTS]
__getattr__, __dir__ = lazy_exports(__name__, EXPORTS, globals())
