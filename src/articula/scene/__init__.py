"""A robot among obstacles: loading from TOML and link-obstacle distances."""

from articula.scene.obstacles import Obstacle
from articula.scene.scene import Scene

__all__ = ["Obstacle", "Scene"]
