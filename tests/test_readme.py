"""README's code runs as written (shortened where it loops in real time)."""

from __future__ import annotations

from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def _block(heading: str) -> str:
    """The first ```python block after `heading` in README.md."""
    after = README.read_text(encoding="utf-8").split(heading, 1)[1]
    return after.split("```python", 1)[1].split("```", 1)[0]


def test_the_live_loop_runs_and_keeps_the_arm_clear_of_the_moving_box():
    code = _block("### A live loop").replace("range(500)", "range(30)")
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)
    controller, scene = namespace["controller"], namespace["controller"].planner.scene
    assert controller.periods == 30
    assert scene.min_distance(namespace["q"], controller.t) > namespace["spec"].d_min
