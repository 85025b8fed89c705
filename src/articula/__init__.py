"""articula: control and decision-making for articulated robots and their soft end-effectors."""

import importlib.metadata

from articula.errors import (
    ArticulaError,
    ConfigError,
    DeviceError,
    GeometryError,
    InfeasibleError,
    ModelError,
)

__version__ = importlib.metadata.version("articula")  # pyproject.toml's, as installed

__all__ = [
    "ArticulaError",
    "ConfigError",
    "DeviceError",
    "GeometryError",
    "InfeasibleError",
    "ModelError",
    "__version__",
]
