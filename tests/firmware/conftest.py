"""Fixtures of the firmware tests: the firmware built with its Makefile, run in simavr."""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from articula.rigs.firmware import FirmwareRig, PinPlant

FIRMWARE = Path(__file__).resolve().parents[2] / "firmware"
TOOLCHAIN = "apt-get install -y gcc-avr avr-libc simavr libsimavr-dev"


@pytest.fixture(scope="session")
def built(tmp_path_factory) -> Path:
    """The build folder of `make -C firmware` (skip without the AVR toolchain and simavr)."""
    if shutil.which("avr-gcc") is None or not Path("/usr/include/simavr/sim_avr.h").is_file():
        pytest.skip(TOOLCHAIN)
    build = tmp_path_factory.mktemp("firmware")
    proc = subprocess.run(["make", "-C", str(FIRMWARE), f"BUILD={build}"], capture_output=True,
                          text=True, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return build


@pytest.fixture
def simavr(built) -> Iterator[Callable[[str], str]]:
    """simavr(name) runs build/<name>.elf in the harness without a plant; its UART0's device
    path. Every harness started is killed after the test."""
    started: list[subprocess.Popen] = []

    def run(name: str) -> str:
        proc = subprocess.Popen([built / "harness", built / f"{name}.elf"],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True)  # fmt: skip
        started.append(proc)
        for line in proc.stdout:  # simavr's own lines first, then ours
            if line.startswith("uart0 at "):
                return line.split()[-1]
        raise AssertionError(f"the harness ended: {proc.wait()}")

    yield run
    for proc in started:
        proc.kill()
        proc.wait(10)


@pytest.fixture
def on_plant(built) -> Iterator[Callable[[str, PinPlant], FirmwareRig]]:
    """on_plant(name, plant): build/<name>.elf in the harness, its pins on `plant`; closed
    after the test."""
    rigs: list[FirmwareRig] = []

    def run(name: str, plant: PinPlant) -> FirmwareRig:
        rigs.append(FirmwareRig(built / f"{name}.elf", plant))
        return rigs[-1]

    yield run
    for rig in rigs:
        rig.close()


@pytest.fixture
def emulated(built, emulate_process) -> Callable[..., tuple[subprocess.Popen, str]]:
    """emulated(rig, *args): `articula emulate RIG --firmware build/<rig>.elf <args>` as a
    process (tests/conftest.py's emulate_process), and the device path of its first line."""

    def run(rig: str, *args: object) -> tuple[subprocess.Popen, str]:
        elf = built / f"{rig.replace('-', '_')}.elf"
        return emulate_process(rig, "--firmware", elf, *args)

    return run
