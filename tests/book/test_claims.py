"""The one Claim type: verdicts, the markdown block, and what `reproduce --json` reports."""

from __future__ import annotations

import pytest

from articula.book.claims import Claim, claims_data, claims_markdown, decide
from articula.errors import ConfigError


@pytest.mark.parametrize(
    ("holds", "verdict"),
    [(True, "reproduced"), (False, "not reproduced"), (None, "inconclusive")],
)
def test_decide_turns_a_rule_outcome_into_a_verdict(holds, verdict):
    claim = decide("k", "the book says", "we measured", "the rule", holds)
    assert claim.verdict == verdict
    assert claim.reproduced is (verdict == "reproduced")


def test_an_unknown_verdict_is_a_config_error_naming_the_field():
    with pytest.raises(ConfigError) as err:
        Claim("k", "b", "o", "r", "maybe")  # type: ignore[arg-type]
    assert err.value.field == "Claim.verdict"


def test_the_markdown_block_has_one_bullet_per_claim_with_its_verdict_first():
    claims = [
        decide("a_key", "book a.", "ours a", "rule a", True, title="Claim A"),
        decide("b", "book b", "ours b.", "rule b", None),
    ]
    lines = claims_markdown(claims, "Claims")
    assert lines[0] == "### Claims"
    assert lines[2] == "- **Reproduced.** Claim A. Book: book a. Ours: ours a. Rule: rule a."
    assert lines[3] == "- **Inconclusive.** b. Book: book b. Ours: ours b. Rule: rule b."


def test_the_json_has_booleans_by_name_and_details_with_exactly_the_five_keys():
    claims = [decide("a", "b", "o", "r", True, title="A"), decide("c", "b", "o", "r", None)]
    data = claims_data(claims)
    assert data["claims"] == {"a": True, "c": False}  # inconclusive is false there
    assert [set(d) for d in data["claims_detail"]] == [
        {"name", "book", "ours", "rule", "verdict"}
    ] * 2
    assert data["claims_detail"][1]["verdict"] == "inconclusive"
