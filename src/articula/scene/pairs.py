"""What a Scene's pair queries return (closest points per cell or per link pair), and the
check of link pairs named in a scene file."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from articula.errors import ConfigError


@dataclass(frozen=True)
class Witnesses:
    """Signed distances (links × obstacles) [m] and the closest points [m, world] per cell.

    Attributes:
        distance: signed distance of each (link, obstacle) cell, shape (links, obstacles) [m].
        on_link: closest point on the link, world, shape (links, obstacles, 3) [m].
        on_obstacle: closest point on the obstacle, world, shape (links, obstacles, 3) [m].
    """

    distance: np.ndarray
    on_link: np.ndarray
    on_obstacle: np.ndarray


@dataclass(frozen=True)
class SelfWitnesses:
    """Signed distance [m] of every checked link pair (a, b) and the closest points [m, world]
    on link a and on link b.

    Attributes:
        distance: signed distance of each checked pair, shape (pairs,) [m].
        on_a: closest point on link a of each pair, world, shape (pairs, 3) [m].
        on_b: closest point on link b of each pair, world, shape (pairs, 3) [m].
    """

    distance: np.ndarray
    on_a: np.ndarray
    on_b: np.ndarray


def link_pairs(
    pairs: Sequence[Sequence[str]], links: list[str], field: str
) -> tuple[tuple[int, int], ...]:
    """Link pairs by name as sorted index pairs into `links`, each once; ConfigError naming
    `field` for an entry that is not two different links of the list.

    Args:
        pairs: the link pairs, each two link names.
        links: names of the links with collision shapes, in order.
        field: the config field the pairs come from, for the error messages.

    Returns:
        The pairs as (a, b) indices into `links`, a < b, sorted and without repeats.
    """
    out = set()
    for pair in pairs:
        if len(pair) != 2:
            raise ConfigError(field, f"each entry needs two link names (got {list(pair)})")
        a, b = pair
        for name in (a, b):
            if name not in links:
                raise ConfigError(
                    field, f"no link {name!r} with collision shapes; the links are {links}"
                )
        if a == b:
            raise ConfigError(field, f"a link cannot collide with itself ({a!r})")
        out.add(tuple(sorted((links.index(a), links.index(b)))))
    return tuple(sorted(out))
