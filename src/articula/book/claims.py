"""One claim type for every chapter: what the book says, what we measured, the rule, the verdict."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

from articula.errors import ConfigError

Verdict = Literal["reproduced", "not reproduced", "inconclusive"]
VERDICTS: tuple[Verdict, ...] = ("reproduced", "not reproduced", "inconclusive")


@dataclass(frozen=True)
class Claim:
    """A claim of the book checked against our runs.

    Attributes:
        name: its key in `reproduce --json` (chapters.<ch>.claims).
        book: what the book says.
        ours: what we measured, with the numbers that decide it.
        rule: how the numbers decide the verdict.
        verdict: reproduced, not reproduced, or inconclusive (the numbers cannot tell).
        title: how the report heads it, when the name is a terse key (default: the name).
    """

    name: str
    book: str
    ours: str
    rule: str
    verdict: Verdict
    title: str = ""

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ConfigError("Claim.verdict", f"unknown {self.verdict!r}; use one of {VERDICTS}")

    @property
    def reproduced(self) -> bool:
        """True only for the verdict "reproduced" (inconclusive counts as not)."""
        return self.verdict == "reproduced"


def decide(
    name: str, book: str, ours: str, rule: str, holds: bool | None, title: str = ""
) -> Claim:
    """A Claim whose verdict is reproduced (True), not reproduced (False) or inconclusive (None)."""
    verdict: Verdict = (
        "inconclusive" if holds is None else "reproduced" if holds else "not reproduced"
    )
    return Claim(name, book, ours, rule, verdict, title)


def claims_markdown(claims: Sequence[Claim], heading: str) -> list[str]:
    """The claims as a markdown section: one bullet each, verdict first."""
    lines = [f"### {heading}", ""]
    for c in claims:
        book, ours, rule = (text.rstrip(". ") for text in (c.book, c.ours, c.rule))
        lines.append(
            f"- **{c.verdict.capitalize()}.** {c.title or c.name}. Book: {book}. Ours: {ours}. "
            f"Rule: {rule}."
        )
    return [*lines, ""]


def claims_data(claims: Sequence[Claim]) -> dict[str, Any]:
    """`claims` (name -> reproduced) and `claims_detail` (one object per claim) for --json."""
    keys = ("name", "book", "ours", "rule", "verdict")  # the title is for the report only
    return {
        "claims": {c.name: c.reproduced for c in claims},
        "claims_detail": [{k: getattr(c, k) for k in keys} for c in claims],
    }
