"""`articula drive --arm twin`: the same drive on the MuJoCo twin in this process, and the
drive's refusals of bad options (one line, exit 2)."""

from __future__ import annotations

import json

import pytest

from tests.drive.fake import scene_file

pytest.importorskip("mujoco", reason='the twin needs the `sim` extra: pip install ".[sim]"')


def test_the_twin_is_driven_in_real_time_and_its_folder_written(cli, tmp_path):
    scene = scene_file(tmp_path, duration=3.0)
    result = cli("drive", str(scene), "--arm", "twin", "--out", str(tmp_path / "run"))
    assert result.returncode == 0, result.stderr
    record = json.loads((tmp_path / "run/record.json").read_text())
    assert record["drive"]["outcome"] == "done"
    assert record["metrics"]["plant_rms_error"] < 0.002  # [m]
    assert record["metrics"]["servo_releases"] > 0


@pytest.mark.parametrize(
    ("options", "named"),
    [(["--arm", "kuka:1.2.3.4"], "--arm"), (["--arm", "twin", "--rate", "333"], "--rate")],
)
def test_a_bad_arm_or_rate_is_one_line_naming_the_option(main_fails, tmp_path, options, named):
    scene = scene_file(tmp_path, duration=3.0)
    line = main_fails("drive", str(scene), *options, "--out", str(tmp_path / "run"))
    assert named in line
    assert not (tmp_path / "run").exists()
