"""The applications layer: everything a user runs, on top of the simulator and the libraries.

The ``sbib`` command line (:mod:`~benchmark.applications.cli` and one ``cli_*`` module per
command family), the main job (:mod:`~.study`), the controller comparison
(:mod:`~.comparison`), the identification study and its validation inside the building
(:mod:`~.identification_study`, :mod:`~.identification_validation`), ensembles and fragility
(:mod:`~.ensemble`, :mod:`~.fragility`) and the bench (:mod:`~.speed`). Nothing below imports
this layer.
"""
