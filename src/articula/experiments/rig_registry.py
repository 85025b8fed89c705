"""The bench rigs, one entry per kind: its emulated device, the plant behind its firmware's
pins, the experiment its host driver runs, and that driver.

`articula emulate`, `articula rig run` and the firmware benchmarks look a rig up here; adding
a rig is one entry, not a branch in each of them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from articula.errors import ConfigError
from articula.experiments import motor_on_rig, pneunet_on_rig, six_chamber_on_rig
from articula.rigs.emulator import Device, Emulator, Faults
from articula.rigs.firmware import FirmwareRig, PinPlant
from articula.rigs.link import Link
from articula.rigs.pneunet import PneuNetDevice, PneuNetPins
from articula.rigs.protocol import Info, RigKind
from articula.rigs.recorder import Recorder
from articula.rigs.six_chamber import SixChamberDevice, SixChamberPins


@dataclass(frozen=True)
class RigEntry:
    """One kind of bench rig.

    Attributes:
        name: Its name on the command line (`articula emulate NAME`, a recording's rig).
        kind: The kind the rig reports in its INFO.
        experiment: The registered experiment its host driver runs (`articula rig run`).
        device: The Python device of an emulated rig, from a --plant config file or None.
        pins: The simulated plant behind its firmware's pins, from the same and the
            firmware's ELF (the six-chamber's is checked to hold the actuator's fill table).
        channels: The recorder's columns for the rig an INFO describes.
        run_on_rig: One run of an `experiment` config on the rig: (config, link, recorder) ->
            the run's metrics.
    """

    name: str
    kind: RigKind
    experiment: str
    device: Callable[[Path | None], Device]
    pins: Callable[[Path | None, Path], PinPlant]
    channels: Callable[[Info], tuple[str, ...]]
    run_on_rig: Callable[[Any, Link, Recorder], dict[str, float]]

    def emulated(
        self,
        plant: Path | None = None,
        firmware: Path | None = None,
        realtime: bool = False,
        faults: str = "",
        seed: int = 0,
    ) -> Emulator | FirmwareRig:
        """A simulated rig of this kind behind a pseudo-terminal, serving until closed.

        Args:
            plant: A config file of the plant (the rig's experiment's config: its motor,
                [plant] or [actuator]); None: the book's.
            firmware: The rig's firmware ELF to run in simavr; None: the Python device.
            realtime: Pace samples at the rig's period instead of as fast as the host reads.
            faults: Faults injected by the Python device, e.g. "drop=0.01,delay_ms=20".
            seed: Seed of the faults' draws.

        Returns:
            The rig, serving inside a `with` block (`.path` is the port to open).
        """
        if firmware is None:
            return Emulator(self.device(plant), realtime, Faults.parse(faults), seed)
        if faults:
            raise ConfigError(
                "--faults",
                "faults are injected by the Python device, not on firmware; "
                "leave out --firmware or --faults",
            )
        return FirmwareRig(firmware, self.pins(plant, firmware), realtime)


RIGS = {
    entry.name: entry
    for entry in (
        RigEntry(
            "pneunet",
            RigKind.PNEUNET,
            "pneunet.pid",
            lambda plant: PneuNetDevice(pneunet_on_rig.plant_config(plant)),
            lambda plant, elf: PneuNetPins(pneunet_on_rig.plant_config(plant)),
            pneunet_on_rig.channels,
            pneunet_on_rig.run_on_rig,
        ),
        RigEntry(
            "six-chamber",
            RigKind.SIX_CHAMBER,
            "softarm.damping",
            lambda plant: SixChamberDevice(six_chamber_on_rig.plant_config(plant)),
            lambda plant, elf: SixChamberPins(six_chamber_on_rig.plant_config(plant), firmware=elf),
            six_chamber_on_rig.channels,
            six_chamber_on_rig.run_on_rig,
        ),
        RigEntry(
            "motor",
            RigKind.MOTOR,
            "motor.current",
            lambda plant: motor_on_rig.emulated_motor(motor_on_rig.plant_config(plant)),
            lambda plant, elf: motor_on_rig.firmware_motor(motor_on_rig.plant_config(plant)),
            motor_on_rig.channels,
            motor_on_rig.run_on_rig,
        ),
    )
}


def rig_named(name: str) -> RigEntry:
    """The rig called `name`.

    Args:
        name: A rig's name (pneunet, six-chamber, motor).

    Returns:
        Its entry (ConfigError naming RIG and the choices otherwise).
    """
    if name not in RIGS:
        raise ConfigError("RIG", f"no rig called {name!r}; choose one of {', '.join(RIGS)}")
    return RIGS[name]


def rig_running(experiment: str) -> RigEntry:
    """The rig whose host driver runs `experiment`.

    Args:
        experiment: A registered experiment's name.

    Returns:
        Its entry (ConfigError naming the key `experiment` otherwise).
    """
    for entry in RIGS.values():
        if entry.experiment == experiment:
            return entry
    runs = ", ".join(entry.experiment for entry in RIGS.values())
    raise ConfigError("experiment", f"{experiment} does not run on a rig yet; rig runs: {runs}")
