"""Robot models: kinematics from URDF through Pinocchio, collision geometry as convex shapes."""

from articula.robots.model import LinkGeometry, RobotModel

__all__ = ["LinkGeometry", "RobotModel"]
