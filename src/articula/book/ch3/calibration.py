"""Calibrate E and b of the six-chamber actuator to the book's undamped deactuation (Fig. 3.2)."""

from __future__ import annotations

from dataclasses import dataclass

from scipy.optimize import brentq

from articula.book.ch3.book_values import BOOK_PEAK_DEG, BOOK_SETTLING_S
from articula.errors import ModelError
from articula.experiments.six_chamber import DeactuationConfig, run_metrics, simulate_deactuation
from articula.plants.orientation_sensor import OrientationSensorParams
from articula.plants.six_chamber import SixChamberParams


@dataclass(frozen=True)
class Calibration:
    """Calibrated E [Pa] and b [N·m·s/rad], and the undamped peak [deg] and settling [s]."""

    youngs_modulus: float
    damping: float
    peak_deg: float
    settling_s: float


def undamped(params: SixChamberParams) -> dict[str, float]:
    """True-angle metrics of an undamped deactuation of chamber 0 at the supply pressure."""
    config = DeactuationConfig(actuator=params, sensor=OrientationSensorParams(ideal=True))
    return run_metrics(simulate_deactuation(config), config.band_deg)


def calibrate(
    base: SixChamberParams | None = None,
    peak_deg: float = BOOK_PEAK_DEG,
    settling_s: float = BOOK_SETTLING_S,
) -> Calibration:
    """E that gives `peak_deg` past rest, nested in b that gives `settling_s`, δ = 0.

    Everything else (geometry, density, valves, air, supply) is held at `base`. The settling
    time is a staircase in b (one step per half period), so b is bisected to the step that
    crosses `settling_s`.
    """
    base = base or SixChamberParams()

    def with_(E: float, b: float) -> SixChamberParams:
        return base.model_copy(update={"youngs_modulus": E, "damping": b})

    def modulus_for(b: float) -> float:
        return brentq(
            lambda E: undamped(with_(E, b))["peak_true_deg"] - peak_deg, 8e3, 2e5, xtol=1.0
        )

    lo, hi = 1e-4, 4e-3  # b [N·m·s/rad]: settles too slowly at lo, too fast at hi
    for b, slow in ((lo, True), (hi, False)):
        settling = undamped(with_(modulus_for(b), b))["settling_true_s"]
        if (not settling <= settling_s) != slow:  # nan: never settles, too slow
            raise ModelError(
                f"b = {b:g} N·m·s/rad settles in {settling:.3f} s, on the wrong side of "
                f"{settling_s} s: the bracket [{lo:g}, {hi:g}] does not contain the fit"
            )
    for _ in range(30):
        mid = (lo * hi) ** 0.5
        if not undamped(with_(modulus_for(mid), mid))["settling_true_s"] <= settling_s:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.001:
            break
    E = modulus_for(hi)
    m = undamped(with_(E, hi))
    return Calibration(E, hi, m["peak_true_deg"], m["settling_true_s"])
