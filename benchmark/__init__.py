"""Smart base-isolated benchmark building (Narasimhan et al. 2006) with MR dampers.

The package is kept light at import time: submodules are imported on use, so that
``records`` and ``damper`` may import :mod:`benchmark.foundation.errors` without pulling in the
simulator and its compiled kernels.
"""

__version__ = "0.1.0"
__all__ = ["__version__"]
