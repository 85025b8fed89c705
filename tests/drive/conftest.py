"""The drive tests' processes never outlive their test."""

from __future__ import annotations

import pytest

from tests.drive.fake import Process


@pytest.fixture(autouse=True)
def _no_process_left():
    yield
    Process.kill_all()
