"""articula: control and decision-making for articulated robots and their soft end-effectors."""

from articula.errors import (
    ArticulaError,
    ConfigError,
    DeviceError,
    GeometryError,
    InfeasibleError,
    ModelError,
)

__version__ = "0.1.0"

__all__ = [
    "ArticulaError",
    "ConfigError",
    "DeviceError",
    "GeometryError",
    "InfeasibleError",
    "ModelError",
    "__version__",
]
