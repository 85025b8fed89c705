"""Fixtures of the CLI fuzzer: the `fuzz` marker, the fork server, the runner of examples.

`ARTICULA_FUZZ_EXAMPLES` sets the examples per fuzz test (see fuzzing.py);
`ARTICULA_FUZZ_LOG` names a file where every contract violation is appended as a JSON line;
`ARTICULA_FUZZ_SURVEY=1` logs violations instead of failing at the first one per test, so every
example runs (the session still fails, and its summary lists them).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from tests.fuzz import bases, contract
from tests.fuzz.client import ForkServer
from tests.fuzz.fuzzing import Fuzz
from tests.fuzz.inputs import write_toml


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "fuzz: property-based CLI fuzzing through the fork server "
        "(ARTICULA_FUZZ_EXAMPLES sets the examples per test)",
    )


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if contract.SURVEY and contract.found and exitstatus == pytest.ExitCode.OK:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter: Any) -> None:
    if contract.tally:
        terminalreporter.section("fuzz outcomes (examples per command)")
        for command in sorted({c for c, _ in contract.tally}):
            ends = sorted((e, n) for (c, e), n in contract.tally.items() if c == command)
            terminalreporter.line(f"{command}: " + ", ".join(f"{n} {e}" for e, n in ends))
    if contract.SURVEY and contract.found:
        terminalreporter.section(f"fuzz survey: {len(contract.found)} contract violations")
        for line in contract.found:
            terminalreporter.line(line[:300])


@pytest.fixture(scope="session")
def fuzz_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ForkServer]:
    """The fork server, its compiled code warmed by one valid run of each base."""
    root = tmp_path_factory.mktemp("fuzz-server")
    server = ForkServer(root / "server.log")
    try:
        if server.failed_imports:
            pytest.fail("the fuzz server could not import: " + "; ".join(server.failed_imports))
        warm = root / "warm"
        warm.mkdir()
        bases.write_support_files(warm)
        for name, config in {
            "motor": bases.MOTOR_CURRENT,
            "pneunet": bases.PNEUNET_PID,
            "softarm": bases.SOFTARM_DAMPING,
            **bases.PLANS,
        }.items():
            write_toml(warm / f"{name}.toml", config)
            server.warm(["run", f"{name}.toml", "--out", f"out-{name}", "--json"], warm)
        server.warm(["scene", "check", "baornn-circle.toml", "--json"], warm)
        server.warm(["scene", "check", "baornn-circle.toml", "--metric", "vertex"], warm)
        server.warm(["motor", "analyze", "--preset", "table4.1", "--json"], warm)
        yield server
    finally:
        server.close()


@pytest.fixture(scope="session")
def fuzz(fuzz_server: ForkServer, tmp_path_factory: pytest.TempPathFactory) -> Fuzz:
    return Fuzz(fuzz_server, tmp_path_factory.mktemp("fuzz-examples"))
