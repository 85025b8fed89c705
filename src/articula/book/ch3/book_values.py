"""What chapter 3 of the book prints that we compare with: Sects. 3.1 and 3.4, Fig. 3.7."""

from __future__ import annotations

BOOK_PEAK_DEG = 19.0  # Sect. 3.1 (about 20°) and Sect. 3.4 (about 18°)
BOOK_SETTLING_S = 0.95  # Sect. 3.1 (about 0.9 s) and Sect. 3.4 (about 1 s)
BOOK_DELTA = 0.5  # Sect. 3.4: the damping actuation ratio δ of Eq. (3.4) it reports
BOOK_DAMPED_PEAK_DEG = 2.0  # Sect. 3.4: about 2° past rest at δ ≈ 0.5
BOOK_DAMPED_SETTLING_S = 0.5  # Sect. 3.4: about 0.5 s at δ ≈ 0.5
# (peak past rest [deg], settling [s]) at δ = 0 and δ ≈ 0.5, as Fig. 3.7 marks them.
BOOK = {
    0.0: (BOOK_PEAK_DEG, BOOK_SETTLING_S),
    BOOK_DELTA: (BOOK_DAMPED_PEAK_DEG, BOOK_DAMPED_SETTLING_S),
}
# The same as the book words them, for the Fig. 3.7 table.
BOOK_TEXT = {0.0: ("about 18-20", "about 0.9-1"), BOOK_DELTA: ("about 2", "about 0.5")}

CLAIM_GROWS = "damping grows with delta"
CLAIM_BOOK = "about 2 deg and 0.5 s near delta = 0.5"
BOOK_SAYS = {
    CLAIM_GROWS: "a larger damping actuation ratio δ damps the deactuation more (Fig. 3.7)",
    CLAIM_BOOK: "near δ = 0.5 the body swings about 2° past rest and settles in about 0.5 s",
}
