"""`articula scene check SCENE.toml [--q ...] --json`: the clearance summary and one-line errors."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import tomli_w
import trimesh
from scipy.spatial import ConvexHull

from articula.cli import main
from articula.scene.config import build_scene, load_scene_spec
from articula.validation import load_toml

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = ROOT / "src/articula/book/ch1/configs"
TWO_OBSTACLES = CONFIGS / "two_obstacles.toml"
LINK_MESHES = ROOT / "src/articula/robots/data/iiwa14/meshes"
LINKS = [f"iiwa_link_{k}" for k in range(8)]

# Base turned towards the bracket (atan2(0.4, 0.3)), shoulder tilted 1.39 rad: the elbow lands
# inside the bracket.
INTO_BRACKET = (0.927, 1.39, 0.0, 0.0, 0.0, 0.0, 0.0)


def _check_json(out: dict) -> None:
    """The documented keys with the documented types."""
    assert {"ee_position", "min_clearance", "link_clearance", "collides"} <= set(out)
    assert len(out["ee_position"]) == 3
    assert all(isinstance(v, float) for v in out["ee_position"])
    assert isinstance(out["min_clearance"], float)
    assert isinstance(out["collides"], bool)
    assert list(out["link_clearance"]) == LINKS
    assert all(isinstance(v, float) for v in out["link_clearance"].values())
    assert out["min_clearance"] == min(out["link_clearance"].values())
    assert out["collides"] == (out["min_clearance"] < 0)


@pytest.fixture(scope="module")
def check(cli, one_json):
    """check(*args) -> the JSON object of the real `articula scene check *args --json`, each
    command run once for the module (a copy for every caller)."""
    done: dict[tuple[str, ...], str] = {}

    def run(*args) -> dict:
        key = tuple(map(str, args))
        if key not in done:
            proc = cli("scene", "check", *args, "--json")
            assert proc.returncode == 0, proc.stderr
            assert proc.stderr == ""
            done[key] = proc.stdout
        return one_json(done[key])

    return run


@pytest.fixture
def check_in_process(capsys, one_json):
    """The same through `articula.cli.main` in-process (no start-up cost)."""

    def run(*args) -> dict:
        main(["scene", "check", *map(str, args), "--json"])
        captured = capsys.readouterr()
        assert captured.err == ""
        return one_json(captured.out)

    return run


def test_example_scene_at_q0(check):
    out = check(TWO_OBSTACLES)
    _check_json(out)
    np.testing.assert_allclose(out["ee_position"], [0.0, 0.0, 1.306], atol=1e-9)
    assert out["collides"] is False
    assert out["min_clearance"] > 0.1
    # The same numbers as the library, cell by cell.
    scene, q0 = build_scene(load_scene_spec(load_toml(TWO_OBSTACLES)), CONFIGS)
    d = scene.distances(q0)
    assert out["link_clearance"] == dict(zip(LINKS, d.min(axis=1).tolist(), strict=True))
    assert out["obstacle_clearance"] == {"bracket": d[:, 0].min(), "rock": d[:, 1].min()}


def _hull_depth(point: np.ndarray, vertices: np.ndarray) -> float:
    """How deep `point` is inside hull(vertices) [m] (negative: outside)."""
    eq = ConvexHull(vertices).equations
    return float(-(eq[:, :3] @ point + eq[:, 3]).max())


def test_arm_driven_into_the_bracket_collides(check):
    out = check(TWO_OBSTACLES, "--q", ",".join(map(str, INTO_BRACKET)))
    _check_json(out)
    assert out["collides"] is True
    assert out["min_clearance"] < 0
    # By hand: with joints 3-7 at zero the arm is straight; joint 2 tilts it from vertical
    # towards the azimuth q1, so the elbow (link 4's origin) is 0.42 m up the arm from the
    # shoulder at z = 0.36 m.
    q1, q2 = INTO_BRACKET[:2]
    elbow = np.array([0.0, 0.0, 0.36]) + 0.42 * np.array(
        [math.sin(q2) * math.cos(q1), math.sin(q2) * math.sin(q1), math.cos(q2)]
    )
    c, s = math.cos(0.3), math.sin(0.3)  # bracket: rpy = (0, 0, 0.3), position (0.3, 0.4, 0.45)
    bracket = trimesh.load(CONFIGS / "bracket.stl", force="mesh").vertices @ np.array(
        [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]
    ) + [0.30, 0.40, 0.45]
    in_bracket = _hull_depth(elbow, bracket)
    link4 = trimesh.load(LINK_MESHES / "link_4.stl", force="mesh").vertices
    in_link = _hull_depth(np.zeros(3), link4)  # link 4's own origin, in its frame
    assert in_bracket > 0.04 and in_link > 0.01
    # Two balls around one point, of radii the two depths, need at least their sum to part.
    assert out["link_clearance"]["iiwa_link_4"] <= -(in_bracket + in_link)
    assert out["obstacle_clearance"]["bracket"] == out["min_clearance"]
    assert out["obstacle_clearance"]["rock"] > 0


def test_vertex_metric_never_reports_less_than_gjk(check_in_process):
    gjk = check_in_process(TWO_OBSTACLES)
    vertex = check_in_process(TWO_OBSTACLES, "--metric", "vertex")
    _check_json(vertex)
    assert vertex["metric"] == "vertex"
    for link in LINKS:
        assert vertex["link_clearance"][link] >= gjk["link_clearance"][link] - 2e-6


def test_human_readable_output(capsys):
    main(["scene", "check", str(TWO_OBSTACLES)])
    out = " ".join(capsys.readouterr().out.split())  # rich wraps to the terminal width
    assert "iiwa_link_4" in out
    assert "collides: False" in out
    assert "(0.0000, 0.0000, 1.3060) m" in out


def test_q_with_spaces(check_in_process):
    out = check_in_process(TWO_OBSTACLES, "--q", "0, 1.5707963267948966, 0,0,0,0,0")
    np.testing.assert_allclose(out["ee_position"], [1.306 - 0.36, 0.0, 0.36], atol=1e-9)
    assert out["q"] == [0.0, math.pi / 2, 0.0, 0.0, 0.0, 0.0, 0.0]


# ----- bad input: exit status 2 and one stderr line naming the field ----------------------------


def test_missing_scene_file(cli, assert_one_line_error, tmp_path):
    proc = cli("scene", "check", tmp_path / "nowhere.toml", "--json")
    assert_one_line_error(proc, "nowhere.toml", "not found")
    assert proc.stdout == ""


@pytest.mark.parametrize(
    ("q", "words"),
    [
        ("0,0,0", ["--q", "7 joint values"]),
        ("0,0,0,0,0,0,0,0", ["--q", "7 joint values"]),
        ("a,b,c,d,e,f,g", ["--q", "a,b,c,d,e,f,g"]),
        ("0;0;0;0;0;0;0", ["--q"]),
        ("nan,0,0,0,0,0,0", ["--q", "finite"]),
        ("", ["--q"]),
    ],
    ids=["short", "long", "letters", "semicolons", "nan", "empty"],
)
def test_bad_q(main_fails, q, words):
    line = main_fails("scene", "check", TWO_OBSTACLES, "--q", q, "--json")
    for word in words:
        assert word in line, (word, line)


def test_bad_q_through_the_console_script(cli, assert_one_line_error):
    proc = cli("scene", "check", TWO_OBSTACLES, "--q", "0,0,0", "--json")
    assert_one_line_error(proc, "--q", "7 joint values")
    assert proc.stdout == ""


def test_unknown_metric(main_fails):
    line = main_fails("scene", "check", TWO_OBSTACLES, "--metric", "euclid", "--json")
    assert "--metric" in line and "euclid" in line


ROBOT = '[robot]\nbuiltin = "iiwa14"\n'
BAD_SCENES = {
    "unknown_obstacle_key": (
        ROBOT + "[[obstacles]]\nsphere = 0.1\ncolour = 'red'\n",
        ["obstacles.0.colour", "unknown key"],
    ),
    "two_shapes": (
        ROBOT + "[[obstacles]]\nsphere = 0.1\nbox = [1.0, 1.0, 1.0]\n",
        ["obstacles.0", "exactly one", "box", "sphere"],
    ),
    "no_shape": (ROBOT + "[[obstacles]]\nname = 'x'\n", ["obstacles.0", "exactly one"]),
    "negative_sphere": (ROBOT + "[[obstacles]]\nsphere = -0.1\n", ["obstacles.0.sphere"]),
    "zero_box_side": (
        ROBOT + "[[obstacles]]\nbox = [0.1, 0.0, 0.1]\n",
        ["obstacles.0.box.1"],
    ),
    "short_cylinder": (ROBOT + "[[obstacles]]\ncylinder = [0.1]\n", ["obstacles.0.cylinder"]),
    "missing_mesh": (
        ROBOT + "[[obstacles]]\nmesh = 'nowhere.stl'\n",
        ["nowhere.stl", "mesh file not found"],
    ),
    "nan_position": (
        ROBOT + "[[obstacles]]\nsphere = 0.1\nposition = [0.0, nan, 0.0]\n",
        ["obstacles.0.position", "finite"],
    ),
    "short_rpy": (ROBOT + "[[obstacles]]\nsphere = 0.1\nrpy = [0, 0]\n", ["obstacles.0.rpy"]),
    "inf_velocity": (
        ROBOT + "[[obstacles]]\nsphere = 0.1\nvelocity = [0.0, inf, 0.0]\n",
        ["obstacles.0.velocity"],
    ),
    "scale_on_primitive": (
        ROBOT + "[[obstacles]]\nsphere = 0.1\nscale = 2.0\n",
        ["obstacles.0", "scale"],
    ),
    "duplicate_names": (
        ROBOT + "[[obstacles]]\nname = 'a'\nsphere = 0.1\n" * 2,
        ["obstacles", "unique"],
    ),
    "missing_robot": ("[[obstacles]]\nsphere = 0.1\n", ["robot", "missing"]),
    "robot_not_a_table": ("robot = 3\n", ["robot"]),
    "two_robot_sources": (ROBOT + 'urdf = "arm.urdf"\n', ["robot", "exactly one"]),
    "unknown_robot_key": (ROBOT + "speed = 1\n", ["robot.speed", "unknown key"]),
    "unknown_builtin": ('[robot]\nbuiltin = "ur5"\n', ["robot.builtin", "ur5"]),
    "short_q0": (ROBOT + "q0 = [0.0, 0.0]\n", ["robot.q0"]),
    "nan_q0": (ROBOT + "q0 = [0, 0, 0, nan, 0, 0, 0]\n", ["robot.q0"]),
    "missing_urdf": ('[robot]\nurdf = "arm.urdf"\n', ["urdf", "arm.urdf"]),
    "not_toml": ("[robot\n", ["scene.toml", "TOML"]),
}


@pytest.mark.parametrize("case", sorted(BAD_SCENES))
def test_bad_scene_file(main_fails, tmp_path, case):
    text, words = BAD_SCENES[case]
    path = tmp_path / "scene.toml"
    path.write_text(text)
    line = main_fails("scene", "check", path, "--json")
    for word in words:
        assert word in line, (word, line)


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    ("case", "words"),
    [
        ("unknown_obstacle_key", ["obstacles.0.colour"]),
        ("missing_mesh", ["nowhere.stl"]),
        ("missing_robot", ["robot"]),
    ],
)
def test_bad_scene_file_through_the_console_script(
    cli, assert_one_line_error, tmp_path, case, words
):
    path = tmp_path / "scene.toml"
    path.write_text(BAD_SCENES[case][0])
    proc = cli("scene", "check", path, "--json")
    assert_one_line_error(proc, *words)
    assert proc.stdout == ""


def test_relative_mesh_paths_start_at_the_scene_file(tmp_path, monkeypatch, check_in_process):
    # The same scene in another folder, run from a third: meshes are found beside the TOML.
    folder = tmp_path / "elsewhere"
    folder.mkdir()
    for name in ("two_obstacles.toml", "bracket.stl", "rock.stl"):
        shutil.copy(CONFIGS / name, folder / name)
    monkeypatch.chdir(tmp_path)
    moved = check_in_process(Path("elsewhere/two_obstacles.toml"))
    original = check_in_process(TWO_OBSTACLES)
    assert moved["link_clearance"] == original["link_clearance"]


def test_scene_check_reports_joint_limits(check):
    inside = check(TWO_OBSTACLES)
    assert inside["within_limits"] is True
    q = "0,0,0,0,0,0,3.1"
    outside = check(TWO_OBSTACLES, "--q", q)
    assert outside["within_limits"] is False  # joint 7 is limited to ±175° = ±3.054 rad
    (joint,) = outside["outside_limits"]
    assert (joint["joint"], joint["value"]) == ("iiwa_joint_7", 3.1)
    assert (joint["lower"], joint["upper"]) == pytest.approx((-3.0543, 3.0543), abs=1e-4)
    assert inside["outside_limits"] == []


def test_scene_check_warns_of_a_q0_outside_the_joint_limits(capsys, tmp_path):
    """Issue 48: only --json said within_limits: false; the table now comes with one warning
    line naming the joint, its value and its limits (and none for a q0 within them)."""
    config = load_toml(TWO_OBSTACLES)
    for obstacle in config["obstacles"]:
        obstacle["mesh"] = str(CONFIGS / obstacle["mesh"])
    config["robot"]["q0"] = [0.0, 0.5, 0.0, -1.0, 0.0, 0.6, 3.1]
    scene = tmp_path / "scene.toml"
    scene.write_text(tomli_w.dumps(config))
    main(["scene", "check", str(scene)])
    captured = capsys.readouterr()
    assert "iiwa_link_7" in captured.out  # the table as before
    assert captured.err.splitlines() == [
        "warning: robot.q0: iiwa_joint_7 = 3.1000 rad, outside [-3.0543, 3.0543]; plan and "
        "live refuse to start outside the joint limits"
    ]
    main(["scene", "check", str(scene), "--q", "0,0,-2.97,0,0,0,0"])
    assert capsys.readouterr().err.startswith("warning: --q: iiwa_joint_3 = -2.9700 rad,")
    main(["scene", "check", str(TWO_OBSTACLES)])
    assert capsys.readouterr().err == ""


@pytest.mark.slow
def test_many_configurations_from_a_csv_or_parquet_file_give_one_row_each(cli, one_json, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = [[0.0] * 7, [0.0, 0.5, 0.0, -1.0, 0.0, 0.6, 0.0]]
    csv = tmp_path / "q.csv"
    csv.write_text("q_1,q_2,q_3,q_4,q_5,q_6,q_7\n" + "\n".join(",".join(map(str, r)) for r in rows))
    parquet = tmp_path / "q.parquet"
    pq.write_table(pa.table({f"q_{j + 1}": [r[j] for r in rows] for j in range(7)}), parquet)
    singles = [one_json(cli("scene", "check", TWO_OBSTACLES, "--q", ",".join(map(str, r)),
                            "--json").stdout) for r in rows]  # fmt: skip
    for path in (csv, parquet):
        proc = cli("scene", "check", TWO_OBSTACLES, "--q-file", path, "--json")
        assert proc.returncode == 0, proc.stderr
        assert one_json(proc.stdout)["configurations"] == singles


@pytest.mark.parametrize(
    ("content", "words"),
    [("1,2,3\n", ("--q-file", "7 joint values")), ("a,b\nx,y\n", ("--q-file", "numbers"))],
)
def test_a_bad_q_file_is_one_line_naming_the_option(main_fails, tmp_path, content, words):
    path = tmp_path / "q.csv"
    path.write_text(content)
    line = main_fails("scene", "check", TWO_OBSTACLES, "--q-file", path, "--json")
    assert all(w in line for w in words), line


def test_the_table_of_many_configurations_names_every_column(cli, tmp_path):
    csv = tmp_path / "q.csv"
    csv.write_text("q_1,q_2,q_3,q_4,q_5,q_6,q_7\n0,0.5,0,-1,0,0.6,0\n")
    proc = cli("scene", "check", TWO_OBSTACLES, "--q-file", csv, env={"COLUMNS": "200"})
    assert proc.returncode == 0, proc.stderr
    for header in ("row", "min clearance [m]", "self clearance [m]"):
        assert header in proc.stdout, proc.stdout


def test_a_runs_own_trace_is_a_q_file(cli, check_in_process, tmp_path):
    """Issue 48: --q-file refused a run's trace.parquet (its t, phase, x, ... columns); its
    q_1..q_7 are taken, one configuration per period, and the clearances are the run's."""
    import pyarrow.parquet as pq

    config = load_toml(CONFIGS / "circle_two_obstacles.toml")
    for obstacle in config["obstacles"]:
        obstacle["mesh"] = str(CONFIGS / obstacle["mesh"])
    config["planner"] |= {"method": "qp", "duration": 0.3, "settle": 0.1}
    scene = tmp_path / "scene.toml"
    scene.write_text(tomli_w.dumps(config))
    proc = cli("plan", scene, "--out", tmp_path / "run")
    assert proc.returncode == 0, proc.stderr
    trace = pq.read_table(tmp_path / "run" / "trace.parquet").to_pydict()
    q = np.column_stack([trace[f"q_{j + 1}"] for j in range(7)])
    for kind in ("parquet", "csv"):
        path = tmp_path / "run" / "trace.parquet"
        if kind == "csv":  # the same table as CSV, its columns named
            path = tmp_path / "trace.csv"
            names = [n for n in trace if n != "phase"][::-1]  # in any order
            rows = zip(*(trace[n] for n in names), strict=True)
            path.write_text(
                ",".join(names) + "\n" + "\n".join(",".join(map(repr, r)) for r in rows)
            )
        configurations = check_in_process(scene, "--q-file", path)["configurations"]
        np.testing.assert_array_equal([c["q"] for c in configurations], q)
        clearance = [c["min_clearance"] for c in configurations]
        np.testing.assert_allclose(clearance, trace["clearance"], atol=1e-6)


def test_a_q_file_with_another_robots_joints_is_one_line(main_fails, tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = tmp_path / "trace.parquet"
    pq.write_table(pa.table({"t": [0.0], **{f"q_{j + 1}": [0.0] for j in range(6)}}), path)
    line = main_fails("scene", "check", TWO_OBSTACLES, "--q-file", path)
    assert "--q-file" in line and "q_1 to q_7" in line and "not a table" not in line
