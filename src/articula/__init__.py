"""articula: control and decision-making for articulated robots and their soft end-effectors."""

from articula.errors import (
    ArticulaError,
    ConfigError,
    DeviceError,
    GeometryError,
    InfeasibleError,
    ModelError,
)
from articula.numba_cache import refresh_cache

__version__ = "0.1.0"

refresh_cache()  # before any compiled function loads its cache (see numba_cache.py)

__all__ = [
    "ArticulaError",
    "ConfigError",
    "DeviceError",
    "GeometryError",
    "InfeasibleError",
    "ModelError",
    "__version__",
]
