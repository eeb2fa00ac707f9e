"""The force-driven Bouc-Wen oscillator and its benchmark (Noël & Schoukens 2016).

A system of its own beside the MR damper models: a single-degree-of-freedom oscillator with a
Bouc-Wen restoring force, driven by a force and observed through its displacement.

- :mod:`damper.hysteresis.oscillator`: the model (:class:`HystereticOscillator`) and its
  simulation; :mod:`damper.hysteresis.oscillator_kernel` its compiled Newmark kernel;
- :mod:`damper.hysteresis.noel_schoukens`: the benchmark's true system, signals and error measure;
- :mod:`damper.hysteresis.identification`: identification from force and displacement;
- :mod:`damper.hysteresis.files`: its data files (CSV, HDF5) and model JSON.

``sbib hysteresis`` (``benchmark/applications/cli_hysteresis.py``) is its command;
``docs/hysteresis_benchmark.md`` its documentation.
"""
