"""The stated limits: every size or magnitude that is checked before work starts.

Each limit is a default that a config key or a command-line option can raise (named beside
it); docs/reliability.md lists them. They keep a mistyped value from allocating terabytes,
running for hours, or reaching native code (coal, Pinocchio, numba) with numbers it cannot
take.
"""

from __future__ import annotations

MAX_RUNS = 10_000  # configs in one sweep; `articula sweep --max-runs`
MAX_STEPS = 1_000_000  # control periods of one plan; [planner] max_steps
MAX_SERVO_SAMPLES = 2_000_000  # samples of one servo stream (33 min at 1 kHz); [servo] max_samples
MAX_LINKS = 256  # links of a robot; [robot] max_links
MAX_DECOMPOSE_VERTICES = 200_000  # mesh vertices CoACD may decompose; [[obstacles]] max_vertices
MAX_LENGTH = 1e4  # [m] largest |coordinate|, size or scaled mesh extent anywhere in a scene
MIN_SCALE = 1e-6  # smallest mesh scale factor
MAX_SCALE = 1e6  # largest mesh scale factor
MAX_ANGLE = 1e3  # [rad] largest |joint value| or |rpy| accepted
