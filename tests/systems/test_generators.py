"""The committed systems are what their generators write (`python -m system_ssp.systems --check`,
which CI runs over every generator); here the check itself is tested on one generator."""
import shutil

import pytest

from paths import SYSTEMS
from system_ssp.systems.__main__ import check
from system_ssp.systems import generators
from system_ssp.systems.generators import GENERATORS, generate_all


@pytest.fixture()
def committed_copy(tmp_path):
    dest = tmp_path / "systems"
    dest.mkdir()
    for p in SYSTEMS.glob("sunline.ssd"):
        shutil.copy(p, dest / p.name)
    (dest / "parameters").mkdir()
    for p in (SYSTEMS / "parameters").glob("sunline_*.ssv"):
        shutil.copy(p, dest / "parameters" / p.name)
    return dest


def test_check_passes_on_the_committed_files(fmu_paths, committed_copy):
    fmu_dir = fmu_paths["SunlineEphemeris"].parent
    assert check(fmu_dir, only=["sunline"], committed_dir=committed_copy) == []


def test_check_names_a_changed_file_and_a_missing_one(fmu_paths, committed_copy):
    fmu_dir = fmu_paths["SunlineEphemeris"].parent
    ssv = committed_copy / "parameters" / "sunline_ephemeris.ssv"
    ssv.write_text(ssv.read_text().replace('value="', 'value="1', 1))
    (committed_copy / "parameters" / "sunline_spin_x.ssv").unlink()
    problems = check(fmu_dir, only=["sunline"], committed_dir=committed_copy)
    assert len(problems) == 2
    assert str(ssv) in problems[0] or str(ssv) in problems[1]
    assert any("sunline_spin_x.ssv: generated but not committed" in p for p in problems)


def test_check_names_a_committed_file_no_generator_writes(fmu_paths, committed_copy, monkeypatch):
    # with only the sunline generator registered, a stray parameter set is an orphan
    monkeypatch.setattr(generators, "GENERATORS", {"sunline": GENERATORS["sunline"]})
    stray = committed_copy / "parameters" / "stray.ssv"
    stray.write_text((committed_copy / "parameters" / "sunline_ephemeris.ssv").read_text())
    problems = check(fmu_paths["SunlineEphemeris"].parent, committed_dir=committed_copy)
    assert problems == [f"{stray}: committed but no generator writes it"]


def test_unknown_generator_is_refused():
    with pytest.raises(ValueError, match="unknown generator"):
        generate_all(None, only=["nope"])
    assert list(GENERATORS)[0] == "maneuvers"


def test_a_spacecraft_the_thesis_detumble_cannot_settle_is_refused(monkeypatch):
    """The slew cases start from the detumble's end state: a spacecraft whose thesis detumble
    limit-cycles (14 kg with the thesis gains) is a clear error, not a generator that never ends."""
    import dataclasses

    from system_ssp.ssp.writer import GeneratorError
    from system_ssp.systems.generators import maneuvers

    monkeypatch.setattr(maneuvers, "SPACECRAFT", dataclasses.replace(maneuvers.SPACECRAFT, mass=14.0))
    with pytest.raises(GeneratorError, match=r"does not reach its rate tolerance within .* 20 s .*mass 14 kg"):
        maneuvers.detumble_end_state([0.0, 0.0, 0.0, 1.0])
