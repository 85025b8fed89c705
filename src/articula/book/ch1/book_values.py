"""What chapter 1 of the book shows: its runs (Figs. 1.4-1.12) and what it says of each; and
the design of our comparison of every method beside them."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

# The book's three scenes -> our packaged scene files (the book gives no obstacle shapes or
# poses; docs/deviations.md says how ours were placed).
SCENES = {
    "rectangle": "rectangle_one_obstacle.toml",
    "circle": "circle_one_obstacle.toml",
    "two obstacles": "circle_two_obstacles.toml",
}
NO_AVOIDANCE = {"lambda_weight": 0.0, "d_min": 0.0}  # Λ = 0 and no d_min: Sect. 1.4.1


@dataclass(frozen=True)
class Run:
    """One planning run: a scene with [planner] overrides, its title and what the book says."""

    name: str
    scene: str
    overrides: Mapping[str, Any] = field(default_factory=dict)
    title: str = ""
    book: str = ""


BOOK_RUNS = (
    Run("fig1_4_rectangle", "rectangle", NO_AVOIDANCE, "Fig. 1.4: rectangle, Λ = 0",
        "the links collide with the obstacle"),
    Run("fig1_5", "rectangle", {"lambda_weight": 0.002}, "Fig. 1.5: rectangle, Λ = 0.002",
        "no collision; accurate tracking once converged"),
    Run("fig1_6", "rectangle", {"lambda_weight": 0.0002}, "Fig. 1.6: rectangle, Λ = 0.0002",
        "no collision (d_min = 0.002); clearance much smaller than Fig. 1.5"),
    Run("fig1_4_circle", "circle", NO_AVOIDANCE, "Fig. 1.4: circle, Λ = 0",
        "the links collide with the obstacle"),
    Run("fig1_8", "circle", {"lambda_weight": 0.005}, "Fig. 1.8: circle, Λ = 0.005",
        "no collision; accurate tracking once converged"),
    Run("fig1_9", "circle", {"lambda_weight": 0.0005}, "Fig. 1.9: circle, Λ = 0.0005",
        "clearance much smaller than Fig. 1.8"),
    Run("fig1_11", "two obstacles", NO_AVOIDANCE, "Fig. 1.11: two obstacles, Λ = 0",
        "the links collide with the obstacles"),
    Run("fig1_12", "two obstacles", {"lambda_weight": 0.005},
        "Fig. 1.12: two obstacles, Λ = 0.005", "clearance stays above 0.05 m"),
)  # fmt: skip
UNGUARDED = ("fig1_4_rectangle", "fig1_4_circle", "fig1_11")  # Λ = 0: the book shows collisions
GUARDED = ("fig1_5", "fig1_6", "fig1_8", "fig1_9", "fig1_12")  # Λ > 0, d_min = 0.002 m
# Each scene's book Λ is in its file; the faithful BAORNN rows of the comparison reuse these.
BOOK_RUN_OF_SCENE = {"rectangle": "fig1_5", "circle": "fig1_8", "two obstacles": "fig1_12"}
SNAPSHOTS = {"fig1_5": "Fig. 1.7", "fig1_8": "Fig. 1.10"}  # arm snapshots drawn for these runs
SNAPSHOT_TIMES = (0, 5, 15, 25, 35, 45)  # [s]
TWO_OBSTACLE_CLEARANCE = 0.05  # [m], Fig. 1.12


# Our comparison beyond the book: every method on every scene, at the scene's book Λ.
# Faithful iterations per period that cost as many objective evaluations as baornn-improved's
# 10 × (2·3 antenna pairs + 1 step) + 1 warm start = 71: 24 × 3 = 72.
EQUAL_ITERATIONS = 24
# Comparison rows: name -> [planner] overrides (each scene's file gives Λ, d_min and the rest).
METHODS = {
    "baornn": {"method": "baornn"},
    "baornn-improved": {"method": "baornn-improved"},
    "baornn-equal-evaluations": {"method": "baornn", "iterations_per_step": EQUAL_ITERATIONS},
    "pinv": {"method": "pinv"},
    "dls": {"method": "dls"},
    "qp": {"method": "qp"},
}
STOCHASTIC = ("baornn", "baornn-improved", "baornn-equal-evaluations")
FULL_SEEDS = (0, 1, 2, 3, 4)


def slug(scene: str) -> str:
    """A scene name as part of a run name."""
    return scene.replace(" ", "_")
