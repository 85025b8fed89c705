"""The rig registry: each entry's emulated device is the kind it says, over a real
pseudo-terminal and pyserial; its experiment is registered; lookups refuse unknown names."""

from __future__ import annotations

import pytest

from articula.errors import ConfigError
from articula.experiments.rig_registry import RIGS, rig_named, rig_running
from articula.rigs.link import Link
from articula.rigs.recording import RIGS as RECORDING_WORDS
from articula.runs.registry import names


@pytest.mark.parametrize("name", sorted(RIGS))
def test_an_emulated_rig_answers_as_its_entry_says(name):
    entry = rig_named(name)
    with entry.emulated() as emulator, Link(emulator.path, entry.kind) as link:
        assert link.info.rig == entry.kind
        assert len(entry.channels(link.info)) > 0


def test_every_rig_runs_a_registered_experiment_and_is_named_as_recordings_name_it():
    assert {name: entry.kind for name, entry in RIGS.items()} == RECORDING_WORDS
    assert {entry.experiment for entry in RIGS.values()} <= set(names())
    for entry in RIGS.values():
        assert rig_running(entry.experiment) is entry


def test_unknown_rigs_and_experiments_are_refused_by_name():
    with pytest.raises(ConfigError, match="RIG: no rig called 'arm'; choose one of"):
        rig_named("arm")
    with pytest.raises(ConfigError, match=r"experiment: baornn\.plan does not run on a rig"):
        rig_running("baornn.plan")
    with pytest.raises(ConfigError, match="--faults: faults are injected by the Python device"):
        rig_named("six-chamber").emulated(firmware="six_chamber.elf", faults="drop=0.1")
