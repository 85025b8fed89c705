"""What chapter 2 of the book shows: Tables 2.2 and 2.3, its figures and what it claims.

Attributes:
    FREQUENCIES: the reference frequencies of Table 2.3 [Hz].
    KINDS: the controllers: ordinary, piecewise and fuzzy PID, Eqs. (2.2)-(2.4).
    SCHEDULED: the kinds whose gains are scheduled on θ_r.
    METHODS: the tunings: "manual" by hand (Sect. 2.3.2.1), "auto" by Algorithm 1
        (Sect. 2.3.2.2).
    CONTROLLERS: the six controllers of Table 2.3, named "kind-method".
    BOOK_TABLE_2_2: Table 2.2: method -> representative point [°] ("15", "45", "75"; and
        "sequence", the whole range of Fig. 2.6a) -> tuned gains (K_p, K_i, K_d).
    BOOK_TABLE_2_3: Table 2.3: controller -> (median, Q1, Q3) of E over 25 trials [°], one
        per frequency of FREQUENCIES.
    FIG_2_5: title of Fig. 2.5, the manual tuning's steps to 90°.
    FIG_2_6: titles of Figs. 2.6a-d, the four coordinate-descent runs, by tuning key.
    SINUSOID_FIGURES: reference frequency [Hz] -> (file stem, figure) of Figs. 2.7-2.9, one
        trial per controller.
    TRACKING_LIMIT: what the book says of the highest frequency tracked (Sect. 2.4.2.2).
    CLAIMS: claim name -> what the book says of it (Sect. 2.4.2).
"""

from __future__ import annotations

FREQUENCIES = (0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0)  # [Hz], Table 2.3
KINDS = ("ordinary", "piecewise", "fuzzy")  # PID, piecewise PID, fuzzy PID: Eqs. (2.2)-(2.4)
SCHEDULED = ("piecewise", "fuzzy")
METHODS = ("manual", "auto")  # tuned by hand (Sect. 2.3.2.1) or by Algorithm 1 (Sect. 2.3.2.2)
CONTROLLERS = tuple(f"{kind}-{method}" for method in METHODS for kind in KINDS)  # Table 2.3

# Table 2.2: [K_p, K_i, K_d] per representative point [°]; Fig. 2.6a: the whole range.
BOOK_TABLE_2_2 = {
    "manual": {"15": [1.0, 1.0, 0.0], "45": [1.0, 2.0, 0.0], "75": [1.0, 5.0, 0.0]},
    "auto": {
        "15": [1.0, 2.44, 0.0], "45": [1.48, 3.77, 0.0], "75": [1.49, 2.43, 0.0],
        "sequence": [0.5, 1.86, 0.0],
    },
}  # fmt: skip
# Table 2.3: median (Q1, Q3) of E [°] over 25 trials, per controller and frequency.
BOOK_TABLE_2_3 = {
    "ordinary-manual": [(19.03, 16.54, 21.65), (18.94, 17.08, 21.51), (23.08, 20.25, 24.87),
                        (28.40, 24.30, 31.36), (42.56, 38.54, 44.64), (67.66, 57.90, 70.58),
                        (55.78, 53.48, 58.14)],
    "piecewise-manual": [(12.29, 10.50, 13.71), (17.81, 15.20, 21.13), (22.29, 18.10, 25.58),
                         (26.49, 21.38, 33.78), (36.39, 34.53, 38.14), (43.96, 41.53, 48.90),
                         (50.01, 39.66, 53.26)],
    "fuzzy-manual": [(16.37, 13.55, 18.50), (19.22, 15.59, 20.99), (24.67, 20.40, 26.86),
                     (28.48, 26.75, 39.98), (35.47, 32.89, 36.35), (49.13, 44.89, 60.95),
                     (46.20, 41.46, 52.41)],
    "ordinary-auto": [(9.07, 7.49, 12.56), (17.12, 14.31, 19.50), (19.59, 16.77, 21.42),
                      (32.74, 31.32, 34.31), (39.29, 37.78, 43.43), (44.95, 42.14, 46.73),
                      (52.78, 44.87, 60.29)],
    "piecewise-auto": [(11.41, 9.29, 12.88), (13.44, 10.86, 15.32), (16.76, 13.24, 20.05),
                       (26.15, 22.86, 28.03), (34.00, 32.21, 36.40), (42.25, 40.60, 45.66),
                       (52.03, 46.55, 55.71)],
    "fuzzy-auto": [(9.79, 7.86, 12.99), (11.05, 9.21, 14.04), (15.29, 13.42, 18.48),
                   (25.46, 23.01, 29.63), (32.32, 31.02, 35.33), (42.22, 39.99, 44.58),
                   (45.14, 41.80, 39.42)],
}  # fmt: skip

FIG_2_5 = "Fig. 2.5: manual tuning, steps to 90° (chosen in red)"
FIG_2_6 = {  # the four coordinate-descent runs, by tuning key
    "sequence": "Fig. 2.6a: θ_r through 15°, 45°, 75°, 90°",
    "15": "Fig. 2.6b: θ_r = 15° ([0°, 30°))",
    "45": "Fig. 2.6c: θ_r = 45° ([30°, 60°))",
    "75": "Fig. 2.6d: θ_r = 75° ([60°, 90°])",
}
SINUSOID_FIGURES = {  # [Hz] -> (file stem, figure): one trial per controller
    0.05: ("fig2_7", "Fig. 2.7"),
    0.5: ("fig2_8", "Fig. 2.8"),
    5.0: ("fig2_9", "Fig. 2.9"),
}
TRACKING_LIMIT = "tracks up to about 0.5 Hz, cannot follow 5 Hz"  # Sect. 2.4.2.2

# What the book says of each claim (Sect. 2.4.2), by claim name.
CLAIMS = {
    "automatic_beats_manual": "automatic tuning beats manual tuning in most cases",
    "piecewise_fuzzy_beat_ordinary": "piecewise and fuzzy PID beat ordinary PID",
    "error_grows_with_frequency": "the tracking error grows with the reference frequency",
    "kd_zero_optimal": "K_d = 0 is optimal: every tuned gain set ends with K_d = 0 (Table 2.2)",
}
