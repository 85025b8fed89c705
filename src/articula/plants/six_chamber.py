"""Six-chamber parallel soft actuator of chapter 3: parameters, geometry and the body model.

The body obeys V E k² θ + b θ' + I θ'' = V E c P (Sect. 3.2.2) about two bending axes. The
bending vector β = θ·(cos ψ, sin ψ) [rad] points where the top surface tilts to. Chamber i sits
at angle 60°·i on a circle of radius r_p; its volume grows as the body bends away from it,
V_i = V_0 + a_i·β with a_i = −A_c r_p (L_c/L) ê_i (under constant curvature a chamber of length
L_c in a body of length L turns through θ L_c/L), and its gauge pressure pushes with the
generalised force (p_i − p_atm)·a_i, which is the book's V E c P with V E c = A_c r_p L_c/L.
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np
from pydantic import Field, model_validator

from articula.validation import NonNegative, Positive, StrictModel, field_error

CHAMBERS = 6
GAS_CONSTANT = 287.05  # specific gas constant of air [J/(kg·K)]
# Dragon Skin 30 datasheet: 100 % modulus 86 psi; kept to compare with the calibrated E.
DATASHEET_MODULUS = 0.593e6  # [Pa]


class SixChamberParams(StrictModel):
    """Every constant of the actuator, its valves and its air, in SI (pressures gauge, [Pa]).

    Geometry: length, outer_radius and chamber_radius are the book's (Sect. 3.2.1);
    chamber_circle (radius of the circle of chamber centres) and chamber_length are not in the
    book. density is Dragon Skin 30's (1.08 g/cm³). youngs_modulus E and damping b are
    calibrated to the book's undamped deactuation (`six_chamber_calibration`), not the
    datasheet's E. supply is the pump's gauge pressure; orifice_diameter, discharge and
    flow_transition describe each 3/3 valve's orifice; polytropic is the index n of the air;
    stiffening makes the body stiffer with chamber pressure, V E k²·(1 + s Σ p_i⁺/supply).

    Attributes:
        length: body length L [m] (book).
        outer_radius: outer radius of the body [m] (book).
        chamber_radius: radius of each chamber [m] (book).
        chamber_circle: radius r_p of the circle of chamber centres [m].
        chamber_length: chamber length L_c [m], at most `length`.
        density: density of the silicone [kg/m³].
        sensor_mass: mass of the orientation sensor and its radio on the top [kg].
        youngs_modulus: Young's modulus E of the silicone [Pa], calibrated.
        damping: bending damping b [N·m·s/rad], calibrated.
        supply: pump pressure, gauge [Pa].
        atmosphere: atmospheric pressure, absolute [Pa].
        temperature: air temperature T [K].
        polytropic: polytropic index n of the chamber air, in [1, 1.4].
        orifice_diameter: diameter of each valve's orifice [m].
        discharge: discharge coefficient of the orifice, in (0, 1].
        flow_transition: pressure difference below which orifice flow turns linear [Pa].
        stiffening: relative rise s of V E k² per chamber at full supply; 0: none.
    """

    length: Positive = 0.10
    outer_radius: Positive = 0.04
    chamber_radius: Positive = 0.005
    chamber_circle: Positive = 0.025
    chamber_length: Positive = 0.09
    density: Positive = 1080.0
    sensor_mass: NonNegative = 0.02
    youngs_modulus: Positive = 17_390.0
    damping: NonNegative = 2.162e-3
    supply: Positive = 100e3
    atmosphere: Positive = 101_325.0
    temperature: Positive = 293.15
    polytropic: Annotated[float, Field(ge=1.0, le=1.4, allow_inf_nan=False)] = 1.2
    orifice_diameter: Positive = 1.0e-3
    discharge: Annotated[float, Field(gt=0, le=1, allow_inf_nan=False)] = 0.6
    flow_transition: Positive = 500.0
    stiffening: NonNegative = 0.0

    @model_validator(mode="after")
    def _chambers_fit(self) -> SixChamberParams:
        if self.chamber_circle + self.chamber_radius >= self.outer_radius:
            raise field_error(
                "chamber_circle",
                f"chamber_circle + chamber_radius ({self.chamber_circle} + "
                f"{self.chamber_radius} m) must lie inside outer_radius ({self.outer_radius} m)",
            )
        if 2 * self.chamber_radius >= self.chamber_circle:  # neighbours are r_p apart
            raise field_error(
                "chamber_circle",
                f"neighbouring chambers overlap: chamber_circle ({self.chamber_circle} m) must "
                f"exceed twice chamber_radius ({self.chamber_radius} m)",
            )
        if self.chamber_length > self.length:
            raise field_error(
                "chamber_length",
                f"chamber_length ({self.chamber_length} m) must not exceed length "
                f"({self.length} m)",
            )
        return self

    @property
    def chamber_area(self) -> float:
        """A_c [m²], cross-section of one chamber."""
        return math.pi * self.chamber_radius**2

    @property
    def section_area(self) -> float:
        """A [m²], silicone cross-section (disc minus six chambers)."""
        return math.pi * self.outer_radius**2 - CHAMBERS * self.chamber_area

    @property
    def second_moment(self) -> float:
        """I_a [m⁴], second moment of the section about any diameter (isotropic for six holes)."""
        disc = math.pi * self.outer_radius**4 / 4
        # Σ cos²(60°·i) = 3 over the six chambers (parallel-axis theorem).
        holes = CHAMBERS * math.pi * self.chamber_radius**4 / 4
        holes += 3 * self.chamber_area * self.chamber_circle**2
        return disc - holes

    @property
    def volume(self) -> float:
        """V [m³] of silicone in Eq. (3.3)."""
        return self.section_area * self.length

    @property
    def strain_per_angle(self) -> float:
        """k of ε = kθ: radius of gyration over length, so V E k² = E I_a / L (beam bending)."""
        return math.sqrt(self.second_moment / self.section_area) / self.length

    @property
    def stiffness(self) -> float:
        """V E k² [N·m/rad], the bending stiffness of the model of Sect. 3.2.2."""
        return self.volume * self.youngs_modulus * self.strain_per_angle**2

    @property
    def lever(self) -> float:
        """A_c r_p L_c/L [m³/rad]: V E c of Sect. 3.2.2, and the chamber volume gained per radian.

        Under constant curvature the chamber (length L_c) turns through θ L_c/L of the top's θ,
        so its length grows by r_p θ L_c/L.
        """
        return self.chamber_area * self.chamber_circle * self.chamber_length / self.length

    @property
    def strain_per_pressure(self) -> float:
        """c of ε = cP [1/Pa], from V E c = A_c r_p."""
        return self.lever / (self.volume * self.youngs_modulus)

    @property
    def inertia(self) -> float:
        """I [kg·m²] of the bending angle for constant curvature (lateral, slice tilt, sensor)."""
        mu = self.density * self.section_area
        L = self.length
        # Slice at s moves θs²/(2L) sideways and tilts θs/L; the sensor moves θL/2.
        slices = self.density * self.second_moment * L / 3
        return mu * L**3 / 20 + slices + self.sensor_mass * L**2 / 4

    @property
    def chamber_volume(self) -> float:
        """V_0 [m³] of one chamber with the body straight."""
        return self.chamber_area * self.chamber_length

    @property
    def orifice_area(self) -> float:
        """Valve orifice area [m²]."""
        return math.pi * self.orifice_diameter**2 / 4


def chamber_directions() -> np.ndarray:
    """Unit vectors ê_i (6, 2) of the chambers, chamber i at 60°·i.

    Returns:
        The in-plane direction of each chamber, shape (6, 2).
    """
    phi = np.radians(60.0 * np.arange(CHAMBERS))
    return np.column_stack([np.cos(phi), np.sin(phi)])


def volume_gradients(p: SixChamberParams) -> np.ndarray:
    """a_i = ∂V_i/∂β (6, 2) [m³/rad]: a chamber grows when the body bends away from it.

    Args:
        p: actuator constants.

    Returns:
        a_i = −A_c r_p (L_c/L) ê_i for each chamber, shape (6, 2) [m³/rad].
    """
    return -p.lever * chamber_directions()


def static_bend(p: SixChamberParams, gauge: np.ndarray) -> np.ndarray:
    """β [rad] at rest under chamber gauge pressures [Pa], volume changes ignored (Sect. 3.2.2).

    Args:
        p: actuator constants.
        gauge: gauge pressure of each chamber, shape (6,) [Pa].

    Returns:
        The static bending vector β, shape (2,) [rad], from V E k² θ = V E c P.
    """
    return volume_gradients(p).T @ np.asarray(gauge, dtype=float) / p.stiffness  # V E k²θ = V E c P


def gas_stiffness(p: SixChamberParams, sealed_absolute: float) -> float:
    """Bending stiffness [N·m/rad] added by six sealed chambers at one absolute pressure [Pa].

    Args:
        p: actuator constants.
        sealed_absolute: absolute pressure of every sealed chamber [Pa].

    Returns:
        The gas spring's bending stiffness 3 n p (A_c r_p L_c/L)² / V_0 [N·m/rad].
    """
    # dp_i = −n p a_i·dβ / V_0 on each chamber; Σ a_i a_iᵀ = 3 (A_c r_p)² I₂.
    return 3 * p.polytropic * sealed_absolute * p.lever**2 / p.chamber_volume


def natural_frequency(p: SixChamberParams, sealed: bool = False) -> tuple[float, float]:
    """(ω_n [rad/s], ζ) of I θ'' + b θ' + K θ = 0; `sealed` adds the chambers' gas spring.

    Args:
        p: actuator constants.
        sealed: add the stiffness of the six chambers sealed at atmospheric pressure.

    Returns:
        omega_n: undamped natural frequency ω_n [rad/s].
        zeta: damping ratio ζ.
    """
    K = p.stiffness + (gas_stiffness(p, p.atmosphere) if sealed else 0.0)
    return math.sqrt(K / p.inertia), p.damping / (2 * math.sqrt(K * p.inertia))
