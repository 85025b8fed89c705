"""Hypothesis settings shared by the fuzz tests, and the runner of one example.

`ARTICULA_FUZZ_EXAMPLES` sets the examples per fuzz test (default `DEFAULT_EXAMPLES`). The
examples are the same on every run, unless `ARTICULA_FUZZ_RANDOM=1` (to explore: new examples
each run, or those of `pytest --hypothesis-seed=N`).
Examples are not shrunk: each is one mutated field of a valid input, minimal already, and a
shrinker re-running a 60 s hang dozens of times would cost an hour.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, Phase, settings

from tests.fuzz import bases
from tests.fuzz.client import ACCEPT_SECONDS, ForkServer, Outcome
from tests.fuzz.contract import Example, check_contract, listing

DEFAULT_EXAMPLES = 50  # all fuzz tests in about 30 s on two cores (a minute under load)
EXAMPLES = int(os.environ.get("ARTICULA_FUZZ_EXAMPLES", DEFAULT_EXAMPLES))

RANDOM = os.environ.get("ARTICULA_FUZZ_RANDOM", "") not in ("", "0")

# Shared by every fuzz test: the same examples on every run, no example database written.
FUZZ_SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=not RANDOM,
    database=None,
    print_blob=False,
    phases=(Phase.explicit, Phase.reuse, Phase.generate),
    suppress_health_check=list(HealthCheck),
)


class Fuzz:
    """Runs examples through the fork server and checks the contract on each."""

    def __init__(self, server: ForkServer, root: Path) -> None:
        self.server = server
        self.root = root

    def workdir(self) -> Path:
        """A fresh, empty folder for one example, holding the files base configs name."""
        folder = Path(tempfile.mkdtemp(dir=self.root))
        bases.write_support_files(folder)
        return folder

    def check(self, example: Example, timeout: float = ACCEPT_SECONDS) -> Outcome:
        """Run the example and assert the contract; its folder is removed afterwards."""
        before = listing(example.workdir)
        try:
            outcome = self.server.run(example.args, example.workdir, timeout=timeout)
            check_contract(example, outcome, before)
        finally:
            shutil.rmtree(example.workdir, ignore_errors=True)
        return outcome
