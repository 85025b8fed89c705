"""Joint limits a URDF does not state, and where each joint limit comes from.

A URDF gives each joint a speed limit (and an effort limit), but no acceleration or jerk limit.
Without stated ones (the user's, or the arm's datasheet: robots.datasheets), a joint may reach
its speed limit from rest in no less than ACCEL_TIME, and its acceleration limit from zero in
no less than JERK_TIME.

Where a datasheet and the URDF both give a limit, the tighter one holds (`tighter`). Each
limit's source is one of "urdf", "datasheet <name>", "default rule (<key> = <value> s)" and
"user" (a [robot] or [planner] setting).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from articula.errors import ConfigError

__all__ = [
    "ACCEL_TIME",
    "JERK_TIME",
    "URDF",
    "USER",
    "default_sources",
    "published_or_rule",
    "rise_limit",
    "rule_source",
    "sheet_source",
    "tighter",
]

# [s] A Franka's 7.5-20 rad/s² reach its speed limits in 0.1-0.3 s.
ACCEL_TIME = 0.25
# [s] One 10 ms control period (a Franka's is 2 ms: 7500 rad/s³ at 15 rad/s²).
JERK_TIME = 0.01
URDF = "urdf"
USER = "user"


def sheet_source(name: str) -> str:
    """The source of a limit from the datasheet called `name`.

    Args:
        name: the datasheet's key, e.g. "franka-panda".

    Returns:
        "datasheet <name>".
    """
    return f"datasheet {name}"


def rule_source(key: str, rise_time: float) -> str:
    """The source of a limit from the default rule `rise_limit` with `rise_time`.

    Args:
        key: the setting the rise time came from ("accel_time" or "jerk_time").
        rise_time: its value [s].

    Returns:
        "default rule (<key> = <rise_time> s)".
    """
    return f"default rule ({key} = {rise_time:g} s)"


def default_sources(nq: int) -> dict[str, tuple[str, ...]]:
    """The sources of a URDF robot's limits without datasheet or settings: position, velocity
    and effort from the URDF, acceleration and jerk by the default rules.

    Args:
        nq: number of joints.

    Returns:
        One source per joint for each of "position", "velocity", "acceleration", "jerk",
            "effort".
    """
    return {
        "position": (URDF,) * nq,
        "velocity": (URDF,) * nq,
        "acceleration": (rule_source("accel_time", ACCEL_TIME),) * nq,
        "jerk": (rule_source("jerk_time", JERK_TIME),) * nq,
        "effort": (URDF,) * nq,
    }


def rise_limit(limits: np.ndarray, rise_time: float, key: str = "accel_time") -> np.ndarray:
    """The limit of the next derivative that reaches each limit from zero in `rise_time`:
    limit / rise_time (speed → acceleration, acceleration → jerk); inf where a joint has no
    limit (0 or inf).

    Args:
        limits: joint limits, shape (nq,) (e.g. speeds [rad/s or m/s]).
        rise_time: time from zero to the limit [s], > 0.
        key: the setting `rise_time` came from, named in the error.

    Returns:
        The limits of the next derivative, shape (nq,) (e.g. accelerations [rad/s²]).
    """
    if not (np.isfinite(rise_time) and rise_time > 0):
        raise ConfigError(key, f"must be finite and > 0 s (got {rise_time})")
    limits = np.asarray(limits, dtype=float)
    with np.errstate(over="ignore"):  # a limit near the float range has no useful one above
        return np.where(limits > 0, limits / rise_time, np.inf)


def tighter(
    urdf: np.ndarray, published: Sequence[float | None], source: str
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Per joint, the smaller of the URDF's upper limit and the datasheet's, and the source
    of the one that binds (the datasheet's on a tie: the maker's number, which the URDF
    repeats).

    Args:
        urdf: the URDF's limits, shape (nq,), inf for none (e.g. speeds [rad/s]).
        published: the datasheet's, nq values in the same unit, None for none.
        source: the datasheet's source (`sheet_source`).

    Returns:
        The limits, shape (nq,) (inf where neither has one), and one source per joint.
    """
    sheet = np.array([np.inf if p is None else p for p in published], dtype=float)
    binds = [p is not None and s <= u for p, s, u in zip(published, sheet, urdf, strict=True)]
    return np.minimum(urdf, sheet), tuple(source if b else URDF for b in binds)


def published_or_rule(
    published: Sequence[float | None] | None,
    below: np.ndarray,
    rise_time: float,
    key: str,
    name: str | None,
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Per joint, a datasheet's limit where it publishes one, else the limit `below` reached
    from zero in rise_time (`rise_limit`); with each one's source.

    Args:
        published: the datasheet's limits, nq values, None for none; None: no datasheet.
        below: the limits of the derivative below, shape (nq,) (e.g. speeds [rad/s]).
        rise_time: time from zero to a `below` limit [s].
        key: the setting rise_time came from ("accel_time" or "jerk_time").
        name: the datasheet's name (None without one).

    Returns:
        The limits, shape (nq,), and one source per joint.
    """
    rule = rise_limit(below, rise_time, key)
    if published is None:
        return rule, (rule_source(key, rise_time),) * rule.size
    values = np.array([r if p is None else p for p, r in zip(published, rule, strict=True)])
    source = sheet_source(name or "")
    sources = tuple(rule_source(key, rise_time) if p is None else source for p in published)
    return values, sources
