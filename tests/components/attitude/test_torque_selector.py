"""The torque selector between the attitude controllers and the thrusters."""
import pytest

from components.attitude.command_selector import select_command
from fmu_helpers import check_declarations, instantiate

CMDS = {"detumble": (1.0, 2.0, 3.0), "slew": (-1.0, 0.0, 0.5), "tracking": (0.0, -0.2, 0.0)}


def test_selects_the_enabled_controller():
    assert select_command(CMDS, {}) == [0.0, 0.0, 0.0]
    for name in CMDS:
        assert select_command(CMDS, {name: True}) == list(CMDS[name])


def test_two_enabled_is_an_error():
    with pytest.raises(ValueError, match="more than one attitude controller enabled \\(detumble, tracking\\)"):
        select_command(CMDS, {"detumble": True, "tracking": True})


def test_fmu(build_one, tmp_path):
    path = build_one("neighbor_torque_selector.py")
    deps = check_declarations(path)
    assert "slew_enable" in deps["torque_cmd_B[1]"] and "torque_cmd_tracking_B[3]" in deps["torque_cmd_B[1]"]
    fmu, vr = instantiate(path, tmp_path, "selector", initialize=True)
    fmu.setReal([vr[f"torque_cmd_slew_B[{i}]"] for i in (1, 2, 3)], [-1.0, 0.0, 0.5])
    fmu.setBoolean([vr["slew_enable"]], [True])
    assert fmu.getReal([vr[f"torque_cmd_B[{i}]"] for i in (1, 2, 3)]) == [-1.0, 0.0, 0.5]
    fmu.setBoolean([vr["slew_enable"]], [False])
    assert fmu.getReal([vr[f"torque_cmd_B[{i}]"] for i in (1, 2, 3)]) == [0.0, 0.0, 0.0]
    fmu.terminate()
    fmu.freeInstance()
