"""The simulator layer: the benchmark building and its stepping.

:mod:`~benchmark.simulator.structure` (the 24-DOF superstructure), :mod:`~.isolation` (bearings),
:mod:`~benchmark.simulator.devices` (MR dampers at the isolation level),
:mod:`~benchmark.simulator.building` (the assembled building), :mod:`~.linear_model` (its
linearised state space), :mod:`~benchmark.simulator.sensors` (the measurement layout),
:mod:`~benchmark.simulator.stepping` (the compiled kernels), :mod:`~.simulation` (``simulate``),
:mod:`~benchmark.simulator.results` (HDF5), :mod:`~benchmark.simulator.evaluation` (J1-J9),
:mod:`~benchmark.simulator.oracle` (the ``solve_ivp`` oracle) and :mod:`~.plots`.

It uses the libraries ``records``, ``damper`` and ``controllers`` and the foundation; the
applications build on it. Nothing here imports :mod:`benchmark.applications`.
"""
