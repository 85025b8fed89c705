"""Arms driven by a paced servo loop: the Arm interface (arm), the wall-clock pacer (pacing),
the servo thread (servo_loop), braking (braking), the MuJoCo twin as an arm (twin: the `sim`
extra), Universal Robots through ur-rtde (ur: the `ur` extra) and a fake UR controller that
speaks RTDE (ur_fake). Only the interface and the loop load here."""

from articula.arms.arm import Arm, Measured
from articula.arms.pacing import Latency, Pacer
from articula.arms.servo_loop import ServoLoop

__all__ = ["Arm", "Latency", "Measured", "Pacer", "ServoLoop"]
