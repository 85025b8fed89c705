"""`articula live --plant mujoco`: each period's command played on the MuJoCo twin through the
servo stream (sim.twin_arm, as `plan` does under [plant]), its measured joints handed back to
the controller, and the measured arm drawn solid beside the commanded one, which becomes a
see-through ghost (where the two coincide, the measured arm shows)."""

from __future__ import annotations

from typing import Any

import numpy as np
import viser

from articula.experiments.plan import PlanConfig, twin_arm
from articula.loops.online import with_live_obstacles
from articula.robots.urdf_visuals import Visual
from articula.scene.scene import Scene
from articula.viewer import drawing

MEASURED_COLOUR = (70, 130, 230)  # the measured arm: blue, against the commanded arm's orange
COMMANDED_OPACITY = 0.4  # the commanded arm as a ghost over the measured one


class LivePlant:
    """The arm the live page drives under rigid-body dynamics, drawn solid in blue.

    Args:
        server: the viser server the page is served by.
        config: the validated scene file, with [plant] and [servo].
        scene: the robot and obstacles (their starting poses).
        q0: where the arm starts, at rest, shape (n,) [rad].
        visuals: link name -> its meshes, as the commanded arm is drawn.

    Attributes:
        arm: the twin and its servo stream (sim.twin_arm.TwinArm).
        scene: the twin's scene, its obstacles where the page last put them.
        q: the joints measured at the end of the last period, shape (n,) [rad] (continuous
            joints wrapped to (−π, π]).
        frames: the measured arm's link frames on the page, by link name.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        config: PlanConfig,
        scene: Scene,
        q0: np.ndarray,
        visuals: dict[str, list[Visual]],
    ) -> None:
        self.scene, self._poses = with_live_obstacles(scene)
        self.arm: Any = twin_arm(config, self.scene, q0)
        self.q = self.scene.robot.wrap(np.asarray(q0, dtype=float))
        self.frames, _ = drawing.add_robot(server, visuals, "/measured", MEASURED_COLOUR)

    def __call__(self, command: np.ndarray, poses: dict[str, np.ndarray]) -> np.ndarray:
        """Play one period's command with the obstacles where the page holds them.

        Args:
            command: the period's joint set-point, shape (n,) [rad].
            poses: obstacle name -> its pose this period (4×4, world).

        Returns:
            The joints measured at the end of the period, shape (n,) [rad].
        """
        for name, T in poses.items():
            self._poses[name].pose = T
        self.q = self.arm(command)
        return self.q

    def clearance(self) -> float:
        """The measured arm's smallest clearance to the obstacles where they are now.

        Returns:
            The clearance [m] (inf without obstacles).
        """
        return self.scene.clearances(self.q, 0.0)[0] if self.scene.obstacles else np.inf

    def link_moves(self) -> list[tuple[viser.FrameHandle, np.ndarray, np.ndarray]]:
        """Where the measured arm's link frames go on the page.

        Returns:
            (frame, wxyz quaternion, position [m]) for each link drawn.
        """
        poses = self.scene.robot.link_poses(self.q)
        return [(f, *drawing.wxyz_position(poses[n])) for n, f in self.frames.items() if n in poses]
