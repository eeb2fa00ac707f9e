"""Measured damper test data: :class:`~damper.io.data.DamperTest` with its CSV and UTFSM readers
(:mod:`~damper.io.data`) and the Dyke random-voltage records (:mod:`~damper.io.dyke`). SI inside;
units are converted where a file is read."""
