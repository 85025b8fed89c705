"""The fake UR controller against ur-rtde's own client, unmodified: it connects, servoJ
streams, and the fake enforces what a controller enforces (a jump and a joint limit are
protective stops, a stream that stops ends the program under the RTDE watchdog)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.arms import UR10_HOME
from tests.drive.fake import Fake, joints, realtime_here, scene_file, until

rtde_control = pytest.importorskip("rtde_control", reason='needs ur-rtde: pip install ".[ur]"')
rtde_receive = pytest.importorskip("rtde_receive")
pytest.importorskip("mujoco", reason='the fake runs the twin: pip install ".[sim]"')

LOOKAHEAD, GAIN, TICK = 0.03, 500.0, 0.002


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    return scene_file(tmp_path_factory.mktemp("scene"))


def _connect(fake: Fake):
    receive = rtde_receive.RTDEReceiveInterface(fake.host, 500.0)
    control = rtde_control.RTDEControlInterface(fake.host, 500.0)
    return control, receive


def _stream(control, q_from: np.ndarray, q_to: np.ndarray, ticks: int) -> int:
    """servoJ from q_from to q_to along a cosine ramp, paced by the client's own clock,
    until the controller refuses a set-point; how many it took."""
    for k in range(1, ticks + 1):
        period = control.initPeriod()
        s = 0.5 * (1.0 - np.cos(np.pi * k / ticks))
        if not control.servoJ(list(q_from + s * (q_to - q_from)), 0.0, 0.0, TICK, LOOKAHEAD, GAIN):
            return k - 1
        control.waitPeriod(period)
    return ticks


@pytest.mark.slow
def test_the_real_client_connects_and_its_servoj_stream_moves_the_twin(scene, tmp_path):
    fake = Fake(scene, tmp_path)
    control, receive = _connect(fake)
    fake.wait_for("program 'rtde_control' playing")
    q0 = np.array(receive.getActualQ())
    assert q0 == pytest.approx(UR10_HOME, abs=1e-9)
    goal = q0 + np.array([0.2, -0.1, 0.1, 0.0, 0.0, 0.1])
    with realtime_here():
        assert _stream(control, q0, goal, 500) == 500
        for _ in range(200):  # the end held while the arm settles
            period = control.initPeriod()
            control.servoJ(list(goal), 0.0, 0.0, TICK, LOOKAHEAD, GAIN)
            control.waitPeriod(period)
    control.servoStop()
    control.stopScript()
    fake.wait_for("program stopped: stopScript")
    control.disconnect()
    receive.disconnect()
    log = fake.log()
    assert joints(log, "q")[-1] == pytest.approx(goal, abs=2e-3)
    assert not np.any(log["contacts"])


@pytest.mark.slow
def test_a_jump_in_the_set_point_is_a_protective_stop(scene, tmp_path):
    fake = Fake(scene, tmp_path)
    control, receive = _connect(fake)
    fake.wait_for("program 'rtde_control' playing")
    q = np.array(receive.getActualQ())
    q[1] += 0.3  # [rad] in one set-point
    control.servoJ(list(q), 0.0, 0.0, TICK, LOOKAHEAD, GAIN)
    line = fake.wait_for("protective stop")
    assert "shoulder_lift_joint set-point jumps 0.3000 rad" in line
    until(receive.isProtectiveStopped)
    until(lambda: not control.isProgramRunning())  # the client's own view: paused
    assert not control.servoJ(list(q), 0.0, 0.0, TICK, LOOKAHEAD, GAIN)  # refused now
    control.disconnect()
    receive.disconnect()
    log = fake.log()
    assert np.max(np.abs(joints(log, "qc") - UR10_HOME)) < 1e-9  # it never moved


def test_a_set_point_beyond_a_joint_limit_is_a_protective_stop(scene, tmp_path):
    start = [6.2, *UR10_HOME[1:]]  # shoulder_pan 0.083 rad inside its +2π limit
    fake = Fake(scene, tmp_path, start)
    control, receive = _connect(fake)
    fake.wait_for("program 'rtde_control' playing")
    assert _stream(control, np.array(start), np.array([6.3, *UR10_HOME[1:]]), 100) < 100
    line = fake.wait_for("protective stop")
    assert "shoulder_pan_joint" in line and "outside its limits" in line
    control.disconnect()
    receive.disconnect()
    assert np.max(joints(fake.log(), "qc")[:, 0]) <= 2 * np.pi


@pytest.mark.slow
def test_the_program_stops_when_the_stream_stops(scene, tmp_path):
    fake = Fake(scene, tmp_path)
    control, receive = _connect(fake)
    fake.wait_for("program 'rtde_control' playing")
    assert control.setWatchdog(10.0)
    q0 = np.array(receive.getActualQ())
    with realtime_here():
        assert _stream(control, q0, q0 + 0.05, 100) == 100  # then nothing: a sender that hangs
    line = fake.wait_for("program stopped")
    assert "RTDE watchdog: input_int_register_0 not written" in line
    until(lambda: not control.isProgramRunning())
    control.disconnect()
    receive.disconnect()
    log = fake.log()
    qc = joints(log, "qc")
    assert np.max(np.abs(np.diff(qc[-50:], axis=0))) < 1e-12  # the arm brought to rest
