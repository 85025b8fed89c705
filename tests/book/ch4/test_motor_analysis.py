"""`articula motor analyze`: the model of Sect. 4.2 as JSON, and one-line errors (exit 2)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from articula.book.ch4 import motor_analysis
from articula.cli import main
from articula.errors import ConfigError
from articula.plants.dc_motor import TABLE_4_2

TABLES = {
    "table4.1": {"R": 8.35, "K": 0.355, "b": 0.0016, "J": 0.1, "L": 10e-3},
    "table4.2": {"R": 8.35, "K": 0.4485, "b": 0.002, "J": 0.1, "L": 10e-3},
}
TRANSFER_KEYS = {"omega/tau_ex", "omega/V", "i/tau_ex", "i/V"}
# Entry (row, column) of G(s) = (sI − A)⁻¹ B for each key; states [ω, i], inputs [τ_ex, V].
TRANSFER_ENTRY = {"omega/tau_ex": (0, 0), "omega/V": (0, 1), "i/tau_ex": (1, 0), "i/V": (1, 1)}


@pytest.fixture(scope="module")
def analyze(cli, one_json):
    """analyze(*args) -> the JSON object of `articula motor analyze *args --json`, each
    command run once for the module (a fresh object for every caller)."""
    done: dict[tuple[str, ...], str] = {}

    def run(*args: str) -> dict:
        if args not in done:
            proc = cli("motor", "analyze", *args, "--json")
            assert proc.returncode == 0, proc.stderr
            assert proc.stderr == ""
            done[args] = proc.stdout
        return one_json(done[args])

    return run


def _check_analysis(res: dict, p: dict, V: float, tau: float, current: float) -> None:
    """Every number of the analysis against the model of Sect. 4.2, written out by hand."""
    R, K, b, J, L = p["R"], p["K"], p["b"], p["J"], p["L"]
    assert {"A", "B", "poles", "transfer", "steady_state", "omega_c"} <= set(res)

    A = np.array(res["A"], dtype=float)
    B = np.array(res["B"], dtype=float)
    assert isinstance(res["A"], list) and all(isinstance(row, list) for row in res["A"])
    assert isinstance(res["B"], list) and all(isinstance(row, list) for row in res["B"])
    np.testing.assert_allclose(A, [[-b / J, K / J], [-K / L, -R / L]], rtol=1e-12)
    np.testing.assert_allclose(B, [[1 / J, 0.0], [0.0, 1 / L]], rtol=1e-12)

    # Poles are the eigenvalues of A (both real for these motors).
    poles = sorted(float(z) for z in res["poles"])
    np.testing.assert_allclose(poles, sorted(np.linalg.eigvals(A).real), rtol=1e-9)

    tf = res["transfer"]
    assert set(tf) == TRANSFER_KEYS
    for key, entry in tf.items():
        assert set(entry) == {"num", "den"}
        # Highest power first: den = JL s² + (JR + bL) s + (bR + K²).
        np.testing.assert_allclose(entry["den"], [J * L, J * R + b * L, b * R + K**2], rtol=1e-12)
        np.testing.assert_allclose(sorted(np.roots(entry["den"]).real), poles, rtol=1e-6)
        # The polynomials evaluate to (sI − A)⁻¹ B at a few complex frequencies.
        for s in (0.3j, 1.0 + 2.0j, 50.0j, 3000.0):
            G = np.linalg.solve(s * np.eye(2) - A, B)
            got = np.polyval(entry["num"], s) / np.polyval(entry["den"], s)
            np.testing.assert_allclose(got, G[TRANSFER_ENTRY[key]], rtol=1e-9)

    # Steady state (4.8): 0 = A x + B u.
    ss = res["steady_state"]
    x = np.linalg.solve(A, -B @ np.array([tau, V]))
    np.testing.assert_allclose([ss["omega"], ss["i"]], x, rtol=1e-9, atol=1e-12)
    d = b * R + K**2
    assert ss["omega"] == pytest.approx((R * tau + K * V) / d, rel=1e-12)
    assert ss["i"] == pytest.approx((-K * tau + b * V) / d, rel=1e-12)

    assert res["omega_c"] == pytest.approx((V - current * R) / K, rel=1e-12)


# ----- motor analyze: the JSON contract ---------------------------------------------------------


@pytest.mark.parametrize("preset", sorted(TABLES))
def test_motor_analyze_preset_defaults(analyze, preset):
    res = analyze("--preset", preset)
    _check_analysis(res, TABLES[preset], V=12.0, tau=0.0, current=1.0)


def test_motor_analyze_table42_critical_speed_matches_book(analyze):
    res = analyze("--preset", "table4.2")
    assert round(res["omega_c"], 4) == 8.1382


def test_motor_analyze_options_change_the_operating_point(analyze):
    res = analyze(
        "--preset", "table4.1", "--voltage", "6", "--torque", "-0.05", "--current", "0.25"
    )
    _check_analysis(res, TABLES["table4.1"], V=6.0, tau=-0.05, current=0.25)
    default = analyze("--preset", "table4.1")
    assert res["steady_state"]["omega"] != default["steady_state"]["omega"]
    assert res["omega_c"] != default["omega_c"]


def test_motor_analyze_params_file_equals_preset(analyze, write_toml):
    path = write_toml(TABLES["table4.2"], "motor.toml")
    from_file = analyze("--params", str(path))
    from_preset = analyze("--preset", "table4.2")
    for key in ("A", "B", "poles", "transfer", "steady_state", "omega_c"):
        assert from_file[key] == from_preset[key], key


def test_motor_analyze_params_file_without_inductance_uses_default(analyze, write_toml):
    p = {k: v for k, v in TABLES["table4.1"].items() if k != "L"}
    res = analyze("--params", str(write_toml(p, "motor.toml")))
    _check_analysis(res, {**p, "L": 10e-3}, V=12.0, tau=0.0, current=1.0)


def test_motor_analyze_custom_motor(analyze, write_toml):
    p = {"R": 2.0, "K": 0.05, "b": 1e-4, "J": 2e-5, "L": 1e-3}
    res = analyze("--params", str(write_toml(p, "small.toml")), "--voltage", "24")
    _check_analysis(res, p, V=24.0, tau=0.0, current=1.0)


def test_motor_analyze_complex_poles(analyze, write_toml):
    # den = 0.001 s² + 0.01 s + 0.25 has complex roots: poles come back as {"re", "im"}.
    p = {"R": 1.0, "K": 0.5, "b": 0.0, "J": 0.01, "L": 0.1}
    res = analyze("--params", str(write_toml(p, "ringing.toml")))
    assert all(set(z) == {"re", "im"} for z in res["poles"])
    got = [complex(z["re"], z["im"]) for z in res["poles"]]
    want = sorted(np.linalg.eigvals(np.array(res["A"])), key=lambda z: (z.real, z.imag))
    got.sort(key=lambda z: (z.real, z.imag))
    np.testing.assert_allclose(got, want, rtol=1e-9)
    np.testing.assert_allclose(np.sort_complex(np.roots(res["transfer"]["i/V"]["den"])),
                               np.sort_complex(np.array(got)), rtol=1e-9)  # fmt: skip


def test_motor_analyze_prints_complex_poles_as_a_plus_bj(capsys, write_toml):
    p = {"R": 1.0, "K": 0.5, "b": 0.0, "J": 0.01, "L": 0.1}
    main(["motor", "analyze", "--params", str(write_toml(p, "ringing.toml"))])
    poles = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("poles"))
    assert re.fullmatch(r"poles = \[-5\+\d+\.?\d*j, -5-\d+\.?\d*j\]", poles), poles


def test_motor_analyze_in_process_prints_only_json(capsys, one_json):
    main(["motor", "analyze", "--preset", "table4.2", "--json"])
    captured = capsys.readouterr()
    assert captured.err == ""
    res = one_json(captured.out)
    _check_analysis(res, TABLES["table4.2"], V=12.0, tau=0.0, current=1.0)


def test_motor_analyze_human_output_is_not_json(cli):
    proc = cli("motor", "analyze", "--preset", "table4.2")
    assert proc.returncode == 0, proc.stderr
    assert "8.13824" in proc.stdout
    with pytest.raises(json.JSONDecodeError):
        json.loads(proc.stdout)


# ----- bad input: one line on stderr, exit status 2 --------------------------------------------

GOOD = "R = 8.35\nK = 0.4485\nb = 0.002\nJ = 0.1\nL = 0.01\n"
PARAM_FILES = {
    "unknown_key": (GOOD + "X = 1.0\n", ["X", "unknown"]),
    "wrong_type": (GOOD.replace("R = 8.35", 'R = "8.35 ohm"'), ["R"]),
    "nan": (GOOD.replace("R = 8.35", "R = nan"), ["R"]),
    "inf": (GOOD.replace("K = 0.4485", "K = inf"), ["K"]),
    "negative_resistance": (GOOD.replace("R = 8.35", "R = -8.35"), ["R"]),
    "zero_inductance": (GOOD.replace("L = 0.01", "L = 0.0"), ["L"]),
    "negative_friction": (GOOD.replace("b = 0.002", "b = -0.002"), ["b"]),
    "missing_key": (GOOD.replace("J = 0.1\n", ""), ["J", "missing"]),
    "not_toml": ("R = = 8.35\n", ["bad.toml"]),
    "bool_for_number": (GOOD.replace("J = 0.1", "J = true"), ["J"]),
}


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    "case",
    [
        *sorted(PARAM_FILES),
    ],
)
def test_motor_analyze_bad_params_file(cli, tmp_path, assert_one_line_error, case):
    text, names = PARAM_FILES[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    proc = cli("motor", "analyze", "--params", str(path), "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, *names)


BAD_ARGS = {
    "missing_file": (["--params", "{tmp}/nope.toml"], ["nope.toml"]),
    "both_preset_and_params": (["--preset", "table4.2", "--params", "{good}"], ["--preset"]),
    "neither_preset_nor_params": ([], ["--preset", "--params"]),
    "unknown_preset": (["--preset", "table9.9"], ["--preset", "table9.9"]),
    "voltage_not_a_number": (["--preset", "table4.2", "--voltage", "twelve"], ["--voltage"]),
    "torque_not_a_number": (["--preset", "table4.2", "--torque", "x"], ["--torque"]),
    "current_not_a_number": (["--preset", "table4.2", "--current", "1A"], ["--current"]),
    "voltage_nan": (["--preset", "table4.2", "--voltage", "nan"], ["--voltage"]),
    "current_inf": (["--preset", "table4.2", "--current", "inf"], ["--current"]),
    "torque_minus_inf": (["--preset", "table4.2", "--torque=-inf"], ["--torque"]),
    "unknown_option": (["--preset", "table4.2", "--bogus", "1"], ["--bogus"]),
}


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize(
    "args",
    [["--preset", "table4.2", "--current", "2"], ["--preset", "table4.1", "--voltage", "0"]],
    ids=["infeasible_current", "infeasible_at_zero_voltage"],
)
def test_motor_analyze_infeasible_current_keeps_the_rest(cli, args):
    # No speed lets that current flow: omega_c is null with a reason; the model is still shown.
    proc = cli("motor", "analyze", *args, "--json")
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result["omega_c"] is None
    assert "--current" in result["omega_c_note"]
    assert len(result["poles"]) == 2 and set(result["steady_state"]) >= {"omega", "i"}


def _fill(args: list[str], tmp_path: Path) -> list[str]:
    good = tmp_path / "good.toml"
    good.write_text(GOOD)
    return [a.format(tmp=tmp_path, good=good) for a in args]


@pytest.mark.slow_cases(keep=1)
@pytest.mark.parametrize("case", sorted(BAD_ARGS))
def test_motor_analyze_bad_arguments(cli, tmp_path, assert_one_line_error, case):
    args, names = BAD_ARGS[case]
    proc = cli("motor", "analyze", *_fill(args, tmp_path), "--json")
    assert proc.stdout == ""
    assert_one_line_error(proc, *names)


@pytest.mark.parametrize("case", sorted(BAD_ARGS))
def test_motor_analyze_bad_arguments_in_process(main_fails, tmp_path, case):
    args, names = BAD_ARGS[case]
    line = main_fails("motor", "analyze", *_fill(args, tmp_path), "--json")
    assert all(name in line for name in names), line


def test_params_file_that_is_not_utf8_is_one_line(cli, tmp_path, assert_one_line_error):
    path = tmp_path / "bin.toml"
    path.write_bytes(b"\xff\xfeR = 1\n")
    proc = cli("motor", "analyze", "--params", path, "--json")
    assert_one_line_error(proc, "bin.toml")


# ----- the functions behind the command ----------------------------------------------------------


def test_load_params_needs_exactly_one_source(tmp_path):
    with pytest.raises(ConfigError, match="exactly one"):
        motor_analysis.load_params(None, None)
    with pytest.raises(ConfigError, match="exactly one"):
        motor_analysis.load_params("table4.2", tmp_path / "motor.toml")


def test_analyze_rejects_a_non_finite_operating_point():
    with pytest.raises(ConfigError) as exc:
        motor_analysis.analyze(TABLE_4_2, voltage=12.0, torque=float("nan"), current=1.0)
    assert exc.value.field == "--torque"


def test_analyze_reports_an_infeasible_current_as_none_with_a_reason():
    res = motor_analysis.analyze(TABLE_4_2, voltage=12.0, torque=0.0, current=2.0)
    assert res["omega_c"] is None
    assert res["omega_c_note"]
    assert res["steady_state"]["voltage"] == 12.0


def test_params_read_the_motor_table_identify_writes(tmp_path):
    import tomli_w

    plant = {"experiment": "motor.current", "rig": "single", "motor": TABLE_4_2.model_dump(),
             "reference": {"current": 0.5, "speed": 0.0}}  # fmt: skip
    (tmp_path / "plant.toml").write_text(tomli_w.dumps(plant))
    assert motor_analysis.load_params(None, tmp_path / "plant.toml") == TABLE_4_2
    del plant["motor"]["R"]
    (tmp_path / "plant.toml").write_text(tomli_w.dumps(plant))
    with pytest.raises(ConfigError, match=r"motor\.R"):
        motor_analysis.load_params(None, tmp_path / "plant.toml")
