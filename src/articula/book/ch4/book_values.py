"""What chapter 4 of the book prints: the model numbers, its runs (Figs. 4.5-4.9), its claims."""

from __future__ import annotations

# Operating points of Sects. 4.2 and 4.3.
SUPPLY = 12.0  # [V], Eq. (4.9) and Fig. 4.3
CRITICAL_CURRENT = 1.0  # [A] at which ω_c is computed, Sect. 4.3.2
LOAD_TORQUE = -0.3  # [N·m], the external torque of Eq. (4.10)

# Numbers the book prints.
OMEGA_PER_VOLT, CURRENT_PER_VOLT = 2.81, 0.015  # ω_ss/V, i_ss/V: Sect. 4.2.2, Table 4.1
OMEGA_MAX, CURRENT_MAX = 33.72, 0.18  # ω_ss, i_ss at 12 V: Eq. (4.9)
OMEGA_C = 8.1382  # [rad/s], Sect. 4.3.2, Table 4.2 at 12 V and 1 A
RISE_TIME = 0.1  # [s], Fig. 4.5

# The book's runs of Sect. 4.4.1: our config file's stem -> title.
FIGURES = {
    "fig4_5": "Fig. 4.5: constant reference, unfiltered",
    "fig4_6": "Fig. 4.6: sinusoid at 5 rad/s, unfiltered",
    "fig4_7": "Fig. 4.7: sinusoid at 25 rad/s, unfiltered",
    "fig4_8": "Fig. 4.8: constant reference, filtered",
    "fig4_9": "Fig. 4.9: sinusoid at 5 rad/s, filtered",
}
# What the book says of each run (Sect. 4.4.1); it prints only the rise time as a number.
SAYS = {
    "fig4_5": "rise time ≈ 0.1 s; converges quickly; noisy sensor",
    "fig4_6": "tracks the 5 rad/s sinusoid easily",
    "fig4_7": "amplitude falls and a phase lag appears at 25 rad/s",
    "fig4_8": "filtering delays convergence, longer rise time",
    "fig4_9": "magnitude falls and phase lags even at 5 rad/s",
}

# The book's claims, as the claims block quotes them.
SAYS_OMEGA_C = "ω_c = 8.1382 rad/s for Table 4.2 at 12 V and 1 A (Sect. 4.3.2)"
SAYS_PER_VOLT = "ω_ss ≈ 2.81·V rad/s and i_ss ≈ 0.015·V A for Table 4.1, Eq. (4.8)"
SAYS_RISE_TIME = "the current rises in about 0.1 s (Fig. 4.5)"
SAYS_TRACKS = "the unfiltered loop tracks a 5 rad/s sinusoid easily (Fig. 4.6)"
SAYS_AMPLITUDE_FALLS = "at 25 rad/s the amplitude falls (Fig. 4.7)"
SAYS_LAG_GROWS = "at 25 rad/s a phase lag appears (Fig. 4.7)"
SAYS_FILTER_DELAYS = "filtering delays convergence: a longer rise time (Fig. 4.8)"
SAYS_FILTER_COSTS = "with the filter, magnitude falls and phase lags even at 5 rad/s (Fig. 4.9)"
SAYS_LESS_NOISE = "more filtering gives a more accurate (less noisy) fed-back current"
SAYS_LESS_BANDWIDTH = "more filtering costs bandwidth"
