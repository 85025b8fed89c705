"""plants/six_chamber.py: the six-chamber actuator's cross-section against pixel integration, its
model constants from beam bending, the static bend, and parameter checks naming the field."""

from __future__ import annotations

import numpy as np
import pytest

from articula.errors import ConfigError
from articula.plants.six_chamber import (
    CHAMBERS,
    SixChamberParams,
    chamber_directions,
    static_bend,
    volume_gradients,
)

P = SixChamberParams()


def test_second_moment_matches_pixel_integration():
    n = 2001
    x = np.linspace(-P.outer_radius, P.outer_radius, n)
    X, Y = np.meshgrid(x, x)
    solid = np.hypot(X, Y) <= P.outer_radius
    for d in chamber_directions() * P.chamber_circle:
        solid &= (X - d[0]) ** 2 + (Y - d[1]) ** 2 > P.chamber_radius**2
    cell = (x[1] - x[0]) ** 2
    assert P.section_area == pytest.approx(solid.sum() * cell, rel=2e-3)
    assert P.second_moment == pytest.approx((Y**2 * solid).sum() * cell, rel=2e-3)
    assert P.second_moment == pytest.approx((X**2 * solid).sum() * cell, rel=2e-3)


def test_book_model_constants_follow_from_beam_bending():
    # V E k² = E I_a / L and V E c = A_c r_p L_c/L (Sect. 3.2.2 with ε = y κ of a bent beam).
    assert P.stiffness == pytest.approx(P.youngs_modulus * P.second_moment / P.length)
    assert P.volume * P.youngs_modulus * P.strain_per_pressure == pytest.approx(P.lever)
    # Constant curvature: the chamber's axis at r_p from the neutral axis, over its length
    # L_c, lengthens by r_p·(θ L_c/L) when the top turns by θ.
    theta = 0.1
    dv = (volume_gradients(P) @ np.array([-theta, 0.0]))[0]
    assert dv == pytest.approx(P.chamber_area * P.chamber_circle * theta * P.chamber_length
                               / P.length)  # fmt: skip
    assert P.model_copy(update={"chamber_length": P.length}).lever > P.lever


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("chamber_circle", 0.037, "outer_radius"),
        ("chamber_circle", 0.009, "overlap"),
        ("chamber_length", 0.2, "length"),
        ("density", -1.0, "greater than 0"),
    ],
)
def test_bad_geometry_names_the_field(field, value, words):
    with pytest.raises(ConfigError) as exc:
        SixChamberParams(**{field: value})
    message = str(exc.value)
    assert field in message and str(value) in message and words in message


@pytest.mark.parametrize("pair", [(0, 3), (1, 4), (2, 5)])
def test_opposite_equal_pressures_give_no_static_bend(pair):
    gauge = np.zeros(CHAMBERS)
    gauge[list(pair)] = 70e3
    assert np.abs(static_bend(P, gauge)).max() < 1e-15
