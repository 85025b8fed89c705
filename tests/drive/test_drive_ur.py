"""`articula drive --arm ur:HOST` against the fake controller (`articula emulate ur`), both as
processes, ur-rtde's real client between them: the motion tracks and keeps the limits by the
fake's own log, a start off q0 is refused, a continuous joint a turn off is not, Ctrl-C and
SIGTERM end at rest, a killed controller ends the drive in one line with its folder written."""

from __future__ import annotations

import json
import re
import signal
from pathlib import Path

import numpy as np
import pytest

from articula.experiments.plan import build_plan, load_plan
from tests.arms import UR10_HOME, ur10_robot
from tests.drive.fake import DRIVE_PRIORITY, Fake, Process, joints, rt_options, scene_file, until

rtde_receive = pytest.importorskip("rtde_receive", reason='needs ur-rtde: pip install ".[ur]"')
pytest.importorskip("mujoco", reason='the fake runs the twin: pip install ".[sim]"')

H = 0.002  # [s] the fake's cycle


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    return scene_file(tmp_path_factory.mktemp("scene"))


def _drive(scene: Path, fake: Fake, out: Path) -> Process:
    args = ["drive", str(scene), "--arm", f"ur:{fake.host}", "--out", str(out)]
    return Process(*args, *rt_options(DRIVE_PRIORITY))


def _robot(scene: Path):
    return build_plan(load_plan(scene), scene.parent, str(scene)).scene.robot


def _wait_until_moving(fake: Fake) -> None:
    """Wait for the arm to move (read from the controller, as a second RTDE client)."""
    receive = rtde_receive.RTDEReceiveInterface(fake.host, 125.0, ["actual_qd"])
    until(lambda: float(np.max(np.abs(receive.getActualQd()))) > 0.05)
    receive.disconnect()


@pytest.mark.slow
@pytest.mark.parametrize("arm", ["ur10", "ur5", "ur5e"])
def test_the_drive_tracks_within_2_mm_and_keeps_every_limit(tmp_path, arm):
    scene = scene_file(tmp_path, name=arm)
    fake = Fake(scene, tmp_path)
    drive = _drive(scene, fake, tmp_path / "run")
    assert drive.process.wait() == 0, drive.lines
    record = json.loads((tmp_path / "run/record.json").read_text())
    m = record["metrics"]
    assert record["drive"]["outcome"] == "done"
    assert m["plant_rms_error"] < 0.002  # [m] once settled
    assert m["plant_min_clearance"] > 0
    log = fake.log()
    assert not np.any(log["contacts"])
    robot = _robot(scene)
    q = joints(log, "q")
    speed = np.abs(np.diff(q, axis=0)) / H
    assert np.all(speed <= 1.05 * robot.velocity_limit)  # by differences of the measured joints
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
    assert np.max(np.abs(np.diff(q[-20:], axis=0))) / H < 1e-3  # at rest at the end


@pytest.mark.slow
def test_a_start_03_rad_off_q0_is_refused_naming_the_joint_and_nothing_moves(scene, tmp_path):
    start = list(UR10_HOME)
    start[2] += 0.3
    fake = Fake(scene, tmp_path, start)
    drive = _drive(scene, fake, tmp_path / "run")
    assert drive.process.wait() == 2
    assert len(drive.lines) == 1, drive.lines
    line = drive.lines[0]
    assert re.search(
        r"robot\.q0: the arm's elbow_joint is at 1\.8700 rad, robot\.q0 has 1\.5700", line
    )
    qc = joints(fake.log(), "qc")
    assert np.max(np.abs(qc - start)) < 1e-12


@pytest.mark.slow
def test_a_continuous_joint_a_turn_off_q0_is_accepted_and_driven_the_short_way(tmp_path):
    robot = ur10_robot()
    urdf = Path(robot["urdf"]).read_text()
    urdf = urdf.replace('<joint name="wrist_3_joint" type="revolute">',
                        '<joint name="wrist_3_joint" type="continuous">')  # fmt: skip
    (tmp_path / "ur10_continuous.urdf").write_text(urdf)
    scene = scene_file(tmp_path, robot={"urdf": str(tmp_path / "ur10_continuous.urdf")})
    start = [*UR10_HOME[:5], UR10_HOME[5] + 2 * np.pi]
    fake = Fake(scene, tmp_path, start)
    drive = _drive(scene, fake, tmp_path / "run")
    assert drive.process.wait() == 0, drive.lines
    assert not any("protective stop" in line for line in fake.lines)
    q = joints(fake.log(), "q")
    assert np.min(q[:, 5]) > np.pi  # it stayed on its own turn


@pytest.mark.slow
@pytest.mark.parametrize(("sig", "status"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_mid_motion_brings_the_arm_to_rest_then_stops_the_program(
    scene, tmp_path, sig, status
):
    fake = Fake(scene, tmp_path)
    drive = _drive(scene, fake, tmp_path / "run")
    drive.wait_for("streaming to")
    _wait_until_moving(fake)
    assert drive.end(sig) == status, drive.lines
    errors = [line for line in drive.lines if line.startswith("error:")]
    assert len(errors) == 1 and len(drive.lines) == 2, drive.lines  # "streaming", the error
    record = json.loads((tmp_path / "run/record.json").read_text())
    assert record["drive"]["outcome"].startswith(("interrupted", "terminated"))
    fake.wait_for("program stopped: stopScript")
    log = fake.log()
    qc, state = joints(log, "qc"), log["runtime_state"]
    playing = int(np.flatnonzero(state == 2)[0])
    stopped = playing + int(np.argmax(state[playing:] != 2))  # the cycle the program stopped
    assert state[stopped] == 1  # stopped by stopScript (no protective stop: that pauses)
    # the stream's own braking path: at rest when the program stopped, within the limits
    assert np.max(np.abs(qc[stopped] - qc[stopped - 1])) / H < 1e-3
    robot = _robot(scene)
    speed = np.abs(np.diff(joints(log, "q"), axis=0)) / H
    assert np.all(speed <= 1.05 * robot.velocity_limit)
    assert np.max(np.abs(np.diff(joints(log, "q")[-20:], axis=0))) / H < 1e-3


@pytest.mark.slow
def test_a_controller_killed_mid_run_ends_the_drive_in_one_line_with_its_folder(scene, tmp_path):
    fake = Fake(scene, tmp_path)
    drive = _drive(scene, fake, tmp_path / "run")
    drive.wait_for("streaming to")
    _wait_until_moving(fake)
    fake.end(signal.SIGKILL)
    assert drive.process.wait() == 1
    assert len(drive.lines) == 2 and drive.lines[1].startswith("error:"), drive.lines
    assert "ur:" in drive.lines[1]  # "streaming ...", then the one line
    record = json.loads((tmp_path / "run/record.json").read_text())
    assert record["drive"]["outcome"].startswith("the arm failed")
    assert record["drive"]["client_messages"]  # ur-rtde's own lines, kept off the terminal
    assert (tmp_path / "run/trace.parquet").exists()
