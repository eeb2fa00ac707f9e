"""Damper models: the contract (:mod:`~damper.models.base`), the registry and its dispatch kernels
(:mod:`~damper.models.registry`), the voltage laws, one module per model family, and
:mod:`~damper.models.response` (a model driven by a displacement history)."""
