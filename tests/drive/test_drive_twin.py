"""`articula drive --arm twin`: the same drive on the MuJoCo twin in this process, under
real-time scheduling where the machine allows it, and the drive's refusals of bad options
(one line, exit 2)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pytest

from tests.drive.fake import environment, realtime_allowed, rt_options, scene_file

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install ".[sim]"')


def test_the_twin_is_driven_in_real_time_and_its_folder_written(cli, tmp_path):
    scene = scene_file(tmp_path, duration=3.0)
    args = ["drive", str(scene), "--arm", "twin", "--out", str(tmp_path / "run")]
    result = cli(*args, *rt_options(5))
    assert result.returncode == 0, result.stderr
    record = json.loads((tmp_path / "run/record.json").read_text())
    assert record["drive"]["outcome"] == "done"
    assert record["drive"]["scheduling"] == ("SCHED_FIFO 5" if realtime_allowed() else "normal")
    assert record["metrics"]["plant_rms_error"] < 0.002  # [m]
    assert record["metrics"]["servo_releases"] > 0


@pytest.mark.parametrize(
    ("options", "named"),
    [
        (["--arm", "kuka:1.2.3.4"], "--arm"),
        (["--arm", "twin", "--rate", "333"], "--rate"),
        (["--arm", "twin", "--rt-priority", "0"], "--rt-priority"),
        (["--arm", "twin", "--rt-priority", "100"], "--rt-priority"),
    ],
)
def test_a_bad_arm_or_rate_is_one_line_naming_the_option(main_fails, tmp_path, options, named):
    scene = scene_file(tmp_path, duration=3.0)
    line = main_fails("drive", str(scene), *options, "--out", str(tmp_path / "run"))
    assert named in line
    assert not (tmp_path / "run").exists()


def test_real_time_scheduling_not_allowed_is_one_line_naming_the_option_and_the_fix(tmp_path):
    scene = scene_file(tmp_path, duration=3.0)
    command = [sys.executable, "-m", "articula", "drive", str(scene), "--arm", "twin"]
    command += ["--out", str(tmp_path / "run"), "--rt-priority", "10"]
    if os.geteuid() == 0:  # root may: take the capability away, as from an ordinary user
        if shutil.which("setpriv") is None:
            pytest.skip("needs setpriv (util-linux) to run without CAP_SYS_NICE as root")
        command = ["setpriv", "--bounding-set", "-sys_nice", "--inh-caps", "-sys_nice", *command]
    result = subprocess.run(command, capture_output=True, text=True, env=environment())
    assert result.returncode == 2, result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and "--rt-priority" in lines[0] and "CAP_SYS_NICE" in lines[0]
    assert not (tmp_path / "run" / "record.json").exists()  # nothing connected, nothing moved
