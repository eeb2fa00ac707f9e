"""The virtual laboratory: test protocols run on a damper model (:mod:`~damper.lab.laboratory`,
:mod:`~damper.lab.protocols`), measurements on steady loops (:mod:`~damper.lab.loops`) and loop
figures (:mod:`~damper.lab.plots`)."""
