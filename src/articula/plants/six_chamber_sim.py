"""The six-chamber actuator with its 3/3 valves integrated over time (compiled with numba).

State: β (2) [rad], β' (2) [rad/s] and the six absolute chamber pressures [Pa]. Each chamber's
air obeys dp/dt = n/V (R T ṁ − p dV/dt) with V = V_0 + a_i·β, so a closed (holding) chamber is
a gas spring, and flow through the valve orifice (to or from the pump or the atmosphere) is
where the air loses energy. Valves change position only at scheduled events, except in
REGULATE, where the firmware holds a chamber at a target pressure by bang-bang on its 3/3
valve: fill while the chamber is below the target, vent while it is above (a bending body
compresses and expands a held chamber, so holding alone would let its pressure drift).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError
from articula.numba_cache import jit
from articula.plants.six_chamber import CHAMBERS, GAS_CONSTANT, SixChamberParams, volume_gradients

VENT, HOLD, FILL = 0, 1, 2  # the three positions of each 3-port 3-position valve
REGULATE = 3  # firmware mode: FILL below the event's target pressure, VENT above it
# (time [s], chamber, mode) or (time [s], chamber, REGULATE, target gauge pressure [Pa])
Event = tuple[float, int, int] | tuple[float, int, int, float]


@dataclass(frozen=True)
class ValveSchedule:
    """Valve commands: at `times[k]` [s] chamber `chambers[k]` goes to position `modes[k]`.

    `targets[k]` (gauge) [Pa] is the pressure a REGULATE event holds (unused by other modes).

    Attributes:
        times: event times, sorted, shape (k,) [s].
        chambers: chamber index 0-5 of each event, shape (k,).
        modes: valve mode of each event (VENT, HOLD, FILL or REGULATE), shape (k,).
        targets: REGULATE target of each event, gauge, shape (k,) [Pa]; 0 for other modes.
    """

    times: np.ndarray
    chambers: np.ndarray
    modes: np.ndarray
    targets: np.ndarray

    @staticmethod
    def build(
        events: list[tuple[float, int, int] | tuple[float, int, int, float]],
    ) -> ValveSchedule:
        """A schedule from (time [s], chamber, mode[, target gauge Pa]) tuples, sorted by time
        (stable); REGULATE events need a target above 0.

        Args:
            events: (time [s], chamber 0-5, mode) or (time [s], chamber, REGULATE, target
                gauge pressure [Pa]) tuples, in any order.

        Returns:
            The checked schedule, events sorted by time.
        """
        full = [(*e, 0.0) if len(e) == 3 else tuple(e) for e in events]
        for k, (t, chamber, mode, target) in enumerate(full):
            if not (0 <= chamber < CHAMBERS):
                raise ConfigError(
                    f"events[{k}].chamber", f"must be 0-{CHAMBERS - 1} (got {chamber}, t = {t} s)"
                )
            if mode not in (VENT, HOLD, FILL, REGULATE):
                raise ConfigError(
                    f"events[{k}].mode",
                    f"must be VENT {VENT}, HOLD {HOLD}, FILL {FILL} or REGULATE {REGULATE} "
                    f"(got {mode}, t = {t} s)",
                )
            if mode == REGULATE and not (target > 0 and math.isfinite(target)):
                raise ConfigError(
                    f"events[{k}].target", f"REGULATE needs a gauge target > 0 Pa (got {target})"
                )
        ordered = sorted(full, key=lambda e: e[0])
        return ValveSchedule(
            np.array([e[0] for e in ordered], dtype=float),
            np.array([e[1] for e in ordered], dtype=np.int64),
            np.array([e[2] for e in ordered], dtype=np.int64),
            np.array([e[3] for e in ordered], dtype=float),
        )


@dataclass(frozen=True)
class Simulation:
    """Recorded samples: t [s], β (n, 2) [rad], rate β' (n, 2) [rad/s], gauge pressures
    (n, 6) [Pa] and valve modes (n, 6) (VENT, HOLD, FILL or REGULATE).

    Attributes:
        t: sample times, shape (n,) [s].
        beta: bending vector β, shape (n, 2) [rad].
        rate: bending rate β', shape (n, 2) [rad/s].
        gauge: chamber gauge pressures, shape (n, 6) [Pa].
        modes: valve mode of each chamber (VENT, HOLD, FILL or REGULATE), shape (n, 6).
    """

    t: np.ndarray
    beta: np.ndarray
    rate: np.ndarray
    gauge: np.ndarray
    modes: np.ndarray


def _constants(p: SixChamberParams) -> np.ndarray:
    """Flat constants for the compiled right-hand side."""
    return np.array(
        [
            p.inertia,
            p.stiffness,
            p.damping,
            p.chamber_volume,
            p.polytropic,
            GAS_CONSTANT * p.temperature,
            p.discharge * p.orifice_area,
            p.flow_transition,
            p.atmosphere,
            p.atmosphere + p.supply,
            p.stiffening / p.supply,
        ]
    )


def integrate(
    p: SixChamberParams,
    schedule: ValveSchedule,
    duration: float,
    dt: float = 1e-4,
    record_every: int = 10,
    beta0: tuple[float, float] = (0.0, 0.0),
    rate0: tuple[float, float] = (0.0, 0.0),
    modes0: np.ndarray | None = None,
) -> Simulation:
    """Integrate from rest at atmospheric pressure (or β0, β'0) by RK4 with step dt [s].

    Args:
        p: actuator constants.
        schedule: the valve events.
        duration: simulated time [s], > 0.
        dt: RK4 step [s], in (0, 1e-3].
        record_every: keep every record_every-th step (>= 1).
        beta0: initial bending vector β [rad].
        rate0: initial bending rate β' [rad/s].
        modes0: initial valve positions, shape (6,) (VENT, HOLD or FILL); None: all VENT.

    Returns:
        The recorded samples, from t = 0 to `duration`.
    """
    if not (0 < dt <= 1e-3):
        raise ConfigError("dt", f"need 0 < dt <= 1e-3 s (got {dt})")
    if not (duration > 0 and math.isfinite(duration)):
        raise ConfigError("duration", f"need a finite duration > 0 s (got {duration})")
    if record_every < 1:
        raise ConfigError("record_every", f"need an integer >= 1 (got {record_every})")
    steps = round(duration / dt)
    modes = np.full(CHAMBERS, VENT, np.int64) if modes0 is None else np.array(modes0, np.int64)
    if modes.shape != (CHAMBERS,) or not np.isin(modes, (VENT, HOLD, FILL)).all():
        raise ConfigError(
            "modes0",
            f"need {CHAMBERS} valve positions, each VENT {VENT}, HOLD {HOLD} or FILL {FILL} "
            f"(got {modes0!r})",
        )
    y0 = np.concatenate([beta0, rate0, np.full(CHAMBERS, p.atmosphere)])
    t, y, m = _integrate(
        y0,
        modes,
        _constants(p),
        volume_gradients(p),
        schedule.times,
        schedule.chambers,
        schedule.modes,
        schedule.targets + p.atmosphere,
        dt,
        steps,
        record_every,
    )
    return Simulation(t, y[:, 0:2], y[:, 2:4], y[:, 4:] - p.atmosphere, m)


class Stepper:
    """The actuator from rest advanced one RK4 step at a time with valve positions given
    each step (a firmware's pins), exactly as `integrate` advances it between events.

    Args:
        p: actuator constants.
        dt: RK4 step [s].

    Attributes:
        y: state [β (2) [rad], β' (2) [rad/s], absolute chamber pressures (6) [Pa]], shape (10,).
    """

    def __init__(self, p: SixChamberParams, dt: float = 1e-4) -> None:
        self.p, self.dt = p, dt
        self._c, self._a = _constants(p), volume_gradients(p)
        self._none = (np.zeros(0), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
        self.y = np.concatenate([np.zeros(4), np.full(CHAMBERS, p.atmosphere)])

    @property
    def beta(self) -> np.ndarray:
        """The bending vector β (2,) [rad]."""
        return self.y[0:2]

    def advance(self, modes: np.ndarray) -> None:
        """One step dt with the valves at `modes` (6,) (VENT, HOLD or FILL).

        Args:
            modes: valve position of each chamber, shape (6,).
        """
        _, ys, _ = _integrate(
            self.y, np.array(modes, np.int64), self._c, self._a, *self._none, self.dt, 1, 1
        )
        self.y = ys[-1]


@jit(error_model="numpy")
def orifice_flow(upstream: float, downstream: float, rt: float, cda: float, trans: float) -> float:
    """Mass flow [kg/s] through an orifice, sharp-edged above `trans` [Pa], linear below.

    Args:
        upstream: absolute pressure on the source side [Pa].
        downstream: absolute pressure on the receiving side [Pa].
        rt: specific gas constant times temperature, R T [J/kg].
        cda: discharge coefficient times orifice area [m²].
        trans: pressure difference of the turbulent-to-linear transition [Pa].

    Returns:
        The mass flow from upstream to downstream [kg/s], negative when it reverses.
    """
    dp = upstream - downstream
    rho = max(upstream, downstream) / rt  # density on the high side, ideal gas
    return cda * math.sqrt(2.0 * rho) * dp / (dp * dp + trans * trans) ** 0.25


@jit(error_model="numpy")
def _rhs(
    y: np.ndarray, modes: np.ndarray, targets: np.ndarray, c: np.ndarray, a: np.ndarray
) -> np.ndarray:
    inertia, stiff, damp, v0, n, rt, cda, trans, p_atm, p_sup, per_pa = c
    dy = np.empty_like(y)
    inflated = 0.0
    for i in range(6):
        inflated += max(y[4 + i] - p_atm, 0.0)
    stiff = stiff * (1.0 + per_pa * inflated)
    tx = -stiff * y[0] - damp * y[2]
    ty = -stiff * y[1] - damp * y[3]
    for i in range(6):
        p = y[4 + i]
        gauge = p - p_atm
        tx += gauge * a[i, 0]  # generalised force of a chamber, V E c P of Sect. 3.2.2
        ty += gauge * a[i, 1]
        volume = v0 + a[i, 0] * y[0] + a[i, 1] * y[1]
        dvol = a[i, 0] * y[2] + a[i, 1] * y[3]
        if modes[i] == FILL or (modes[i] == REGULATE and p < targets[i]):
            mdot = orifice_flow(p_sup, p, rt, cda, trans)
        elif modes[i] == VENT or (modes[i] == REGULATE and p > targets[i]):
            mdot = orifice_flow(p_atm, p, rt, cda, trans)
        else:
            mdot = 0.0
        dy[4 + i] = n / volume * (rt * mdot - p * dvol)  # polytropic air in a moving chamber
    dy[0] = y[2]
    dy[1] = y[3]
    dy[2] = tx / inertia  # I θ'' = V E c P − V E k² θ − b θ' (Sect. 3.2.2)
    dy[3] = ty / inertia
    return dy


@jit(error_model="numpy")
def _integrate(
    y0: np.ndarray,
    modes: np.ndarray,
    c: np.ndarray,
    a: np.ndarray,
    ev_t: np.ndarray,
    ev_c: np.ndarray,
    ev_m: np.ndarray,
    ev_p: np.ndarray,
    dt: float,
    steps: int,
    every: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n_rec = steps // every + 1
    ts = np.empty(n_rec)
    ys = np.empty((n_rec, y0.size))
    ms = np.empty((n_rec, 6), np.int64)
    targets = np.zeros(6)  # absolute [Pa] of each chamber's REGULATE target
    y = y0.copy()
    k = 0
    rec = 0
    for step in range(steps + 1):
        t = step * dt
        while k < ev_t.size and ev_t[k] <= t + 0.5 * dt:
            modes[ev_c[k]] = ev_m[k]
            targets[ev_c[k]] = ev_p[k]
            k += 1
        if step % every == 0:
            ts[rec] = t
            ys[rec] = y
            ms[rec] = modes
            rec += 1
        if step == steps:
            break
        k1 = _rhs(y, modes, targets, c, a)
        k2 = _rhs(y + 0.5 * dt * k1, modes, targets, c, a)
        k3 = _rhs(y + 0.5 * dt * k2, modes, targets, c, a)
        k4 = _rhs(y + dt * k3, modes, targets, c, a)
        y = y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return ts[:rec], ys[:rec], ms[:rec]


def fill_time(p: SixChamberParams, gauge: float, dt: float = 1e-5) -> float:
    """Valve open time [s] that fills a still, straight chamber from 0 to `gauge` [Pa].

    The firmware sets a pressure by the fill valve's open time (Sect. 3.2.3: expansion grows
    with the open time); this is that time for the modelled orifice. inf at or above supply.

    Args:
        p: actuator constants.
        gauge: target gauge pressure [Pa].
        dt: integration step [s].

    Returns:
        The open time [s]; 0 for gauge <= 0, inf at or above the supply pressure.
    """
    if gauge <= 0:
        return 0.0
    if gauge >= p.supply * (1 - 1e-6):
        return math.inf
    return float(_fill_time(_constants(p), p.atmosphere + gauge, dt))


@jit(error_model="numpy")
def _fill_time(c: np.ndarray, target: float, dt: float) -> float:
    v0, n, rt, cda, trans, p_atm, p_sup = c[3], c[4], c[5], c[6], c[7], c[8], c[9]
    p = p_atm
    t = 0.0
    while True:
        dp = n / v0 * rt * orifice_flow(p_sup, p, rt, cda, trans)
        if p + dt * dp >= target:
            return t + (target - p) / dp  # linear within the last step
        p += dt * dp
        t += dt
