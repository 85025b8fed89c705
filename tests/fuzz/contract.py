"""The CLI contract every fuzzed command must keep, checked on how it ended.

The contract: a command ends with exit status 0, or with exit status 2 and exactly one
non-empty stderr line starting `error:`; never a traceback, never a signal, never longer than
`REFUSE_SECONDS` before a refusal nor its time limit (client.ACCEPT_SECONDS) before a
success, never over the memory limit (client.MEMORY, RLIMIT_AS) or the process limit
(server.MAX_PROCESSES) of the server's children, and no process of its own is left running
after it exited. After a refusal nothing
was written (the example's folder holds what it held before, so its fresh --out folder does
not exist); whatever the outcome, no file that was there before (inputs, a user's files in
an existing --out folder) was changed or removed. With --json, a success prints one JSON
object and nothing on stderr (not even a warning), and the numbers a valid input always
defines (`finite`) are numbers, not null (and counts that must be positive, `positive`, are).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tests.fuzz.client import Outcome, signal_name
from tests.fuzz.server import MAX_PROCESSES

REFUSE_SECONDS = 5.0  # [s] a refusal comes within this ("a few seconds")
# Where contract violations are appended as JSON lines (every one, not only the first one
# hypothesis reports), when set.
LOG_ENV = "ARTICULA_FUZZ_LOG"
# Survey mode ("1"): a violation is logged and counted instead of failing its test, so that
# every example runs and the log lists every failure class at once; the session still ends
# with a failure status when anything was found (see conftest.pytest_sessionfinish).
SURVEY_ENV = "ARTICULA_FUZZ_SURVEY"
SURVEY = os.environ.get(SURVEY_ENV, "") not in ("", "0")
found: list[str] = []  # one line per violation seen in this session
tally: Counter[tuple[str, str]] = Counter()  # (command, how it ended) -> examples


def listing(folder: Path) -> dict[str, str]:
    """Every path under `folder` (relative) with a digest of its content ("dir" for folders)."""
    found = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            found[os.path.relpath(os.path.join(root, name), folder)] = "dir"
        for name in files:
            path = os.path.join(root, name)
            with contextlib.suppress(OSError), open(path, "rb") as f:  # unless removed meanwhile
                found[os.path.relpath(path, folder)] = hashlib.sha1(f.read()).hexdigest()
    return found


@dataclass
class Example:
    """One fuzzed command: what ran, where, and the inputs to show when it breaks the contract.

    Attributes:
        command: the test's name for the command ("run motor.current", "sweep", ...).
        args: argv after `articula`.
        workdir: the example's own folder (the child's working folder).
        out: its --out folder, which must not exist after a refusal, or None.
        as_json: --json was given.
        finite: dotted paths into the JSON answer that a success must hold as numbers
            (a list's items all numbers).
        inputs: file name -> text of the input files written for it, for the report.
        mutation: what was changed from the valid base, for the report.
        positive: dotted paths into the JSON answer that a success must hold as numbers > 0.
    """

    command: str
    args: list[str]
    workdir: Path
    out: Path | None = None
    as_json: bool = False
    finite: Sequence[str] = ()
    inputs: dict[str, str] = field(default_factory=dict)
    mutation: str = ""
    positive: Sequence[str] = ()

    def report(self, outcome: Outcome, problems: Iterable[str]) -> str:
        """A readable account of a contract violation."""
        lines = [f"articula {self.command}: {'; '.join(problems)}"]
        lines.append(f"  mutation: {self.mutation}")
        lines.append(f"  argv: articula {' '.join(_short(a) for a in self.args)}")
        lines.append(f"  ended: {outcome.describe()}")
        for name, text in self.inputs.items():
            lines.append(f"  --- {name} ---")
            lines.extend("  " + line for line in _short(text, 1500).splitlines())
        lines.append("  --- stderr (head) ---")
        lines.extend("  " + line for line in _short(outcome.stderr, 3000).splitlines()[:40])
        if outcome.status == 0:
            lines.append("  --- stdout (head) ---")
            lines.append("  " + _short(outcome.stdout, 600))
        return "\n".join(lines)


def _short(text: str, limit: int = 200) -> str:
    return text if len(text) <= limit else f"{text[:limit]}… [{len(text)} characters]"


def check_contract(example: Example, outcome: Outcome, before: Mapping[str, str]) -> None:
    """Assert the CLI contract for one example; `before` is listing(workdir) before it ran."""
    problems = violations(example, outcome, before)
    ended = f"exit {outcome.status}" if outcome.status is not None else "killed"
    tally[example.command, ended] += 1
    if problems:
        report = example.report(outcome, problems)
        _log(example, outcome, problems)
        found.append(f"{example.command} | {example.mutation} | {'; '.join(problems)}")
        if not SURVEY:
            raise AssertionError(report)


def violations(example: Example, outcome: Outcome, before: Mapping[str, str]) -> list[str]:
    """Every way `outcome` breaks the contract (empty when it keeps it)."""
    problems: list[str] = []
    if outcome.too_many_processes:
        problems.append(f"ran {outcome.processes} processes at once (limit {MAX_PROCESSES})")
    elif outcome.timed_out:
        problems.append(f"no answer within {outcome.wall:.0f} s (hang or unbounded work)")
    elif outcome.signal is not None:
        problems.append(f"killed by {signal_name(outcome.signal)}")
    elif outcome.status not in (0, 2) and not (outcome.status == 4 and example.command == "plan"):
        # 4: a plan whose motion collides (its run folder is written): a result, not a crash
        problems.append(f"exit status {outcome.status}, expected 0 or 2")
    if outcome.leftover and outcome.status is not None:
        problems.append("processes of its process group outlived it (pool workers?)")
    if "Traceback (most recent call last)" in outcome.stderr:
        problems.append(f"traceback on stderr ({_last_exception(outcome.stderr)})")
    after = listing(example.workdir)
    touched = sorted(k for k in before if after.get(k) != before[k])
    if touched:
        problems.append(f"changed or removed files it did not write: {', '.join(touched[:5])}")
    if outcome.status == 2:
        lines = outcome.stderr.splitlines()
        if len(lines) != 1:
            problems.append(f"refusal with {len(lines)} stderr lines, expected one")
        if not lines or not lines[0].startswith("error:") or not lines[0][6:].strip():
            problems.append("refusal whose stderr does not start with a non-empty `error:` line")
    if outcome.status == 2 and _not_tracked(example.out):
        # A run that did not track its path is a result, written and marked (issue 42).
        if "is written" not in outcome.stderr:
            problems.append("a not-tracked run whose error line does not name its folder")
    elif outcome.status == 2:
        if outcome.wall > REFUSE_SECONDS:
            problems.append(f"refusal after {outcome.wall:.1f} s (limit {REFUSE_SECONDS:g} s)")
        if example.out is not None and _exists(example.out):
            problems.append(f"refusal left its --out folder {example.out.name}/ behind")
        written = sorted(set(after) - set(before))
        if written:
            problems.append(f"refusal wrote {', '.join(written[:5])}")
    if outcome.status == 0 and example.as_json:
        problems.extend(_json_problems(example, outcome))
    return problems


def _not_tracked(out: Path | None) -> bool:
    """Whether `out` holds a complete run folder whose record says it did not track."""
    try:
        record = json.loads((out / "record.json").read_text(encoding="utf-8"))
    except (OSError, ValueError, TypeError):
        return False
    return isinstance(record, dict) and "not_tracked" in record and record.get("complete", True)


def _exists(path: Path) -> bool:
    """os.path.lexists, False for a name the file system cannot even hold (too long)."""
    try:
        os.lstat(path)
    except OSError:
        return False
    return True


def _json_problems(example: Example, outcome: Outcome) -> list[str]:
    if outcome.stderr.strip():
        first = outcome.stderr.strip().splitlines()[0]
        return [f"--json success with output on stderr: {_short(first, 160)!r}"]
    text = outcome.stdout.strip()
    try:
        obj, end = json.JSONDecoder().raw_decode(text)
    except ValueError:
        return [f"--json success whose stdout is not JSON: {_short(text, 160)!r}"]
    if end != len(text) or not isinstance(obj, dict):
        return ["--json success whose stdout is not one JSON object"]
    problems = []
    bad = [p for p in example.finite if not _all_numbers(_lookup(obj, p))]
    if bad:
        problems.append(f"accepted, but {', '.join(bad)} not a finite number (null)")
    for path in example.positive:
        value = _lookup(obj, path)
        if not _all_numbers(value) or value <= 0:
            problems.append(f"accepted, but {path} = {value!r}, expected > 0")
    return problems


def _lookup(obj: Any, dotted: str) -> Any:
    for part in dotted.split("."):
        if not isinstance(obj, dict) or part not in obj:
            return None
        obj = obj[part]
    return obj


def _all_numbers(value: Any) -> bool:
    if isinstance(value, list):
        return bool(value) and all(_all_numbers(v) for v in value)
    if isinstance(value, dict):  # a complex pole {"re", "im"}
        return bool(value) and all(_all_numbers(v) for v in value.values())
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _last_exception(stderr: str) -> str:
    """The exception line of the last traceback on stderr."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    tail = stderr.split("Traceback (most recent call last)")[-1].splitlines()
    for line in reversed(tail):
        if line and not line.startswith(" ") and ":" in line:
            return _short(line.strip(), 160)
    return _short(lines[-1].strip(), 160) if lines else "?"


def _fault_report(stderr: str) -> str:
    """faulthandler's report of a native crash (the Python frames), without its module list."""
    start = stderr.find("Fatal Python error")
    if start < 0:
        return ""
    end = stderr.find("Extension modules", start)
    return stderr[start : end if end > 0 else start + 3000][:3000]


def _log(example: Example, outcome: Outcome, problems: Sequence[str]) -> None:
    path = os.environ.get(LOG_ENV)
    if not path:
        return
    entry = {
        "command": example.command,
        "mutation": example.mutation,
        "args": [_short(a) for a in example.args],
        "problems": list(problems),
        "status": outcome.status,
        "signal": outcome.signal,
        "timed_out": outcome.timed_out,
        "wall": round(outcome.wall, 3),
        "stderr_head": _short(outcome.stderr, 1500),
        "stderr_tail": outcome.stderr[-1500:],
        "crash": _fault_report(outcome.stderr),
        "inputs": {k: _short(v, 2000) for k, v in example.inputs.items()},
    }
    with open(path, "a", encoding="utf-8") as f:
        f.write(json.dumps(entry) + "\n")
