"""The thrusters one by one (thesis Figures 16-19, Eq. 13, 16, 74): the geometry gives the pair
torques with no net force, misalignment and force errors give real hardware's torques and
forces, the minimum on-time holds a firing, and the propellant is counted per thruster."""
import math

import numpy as np
import pytest

from components.attitude import thruster_control as tc
from components.attitude.thruster_set import ThrusterSet, allocation_table, thesis_layout
from components.attitude.thrusters import ThrusterPairs


def test_thesis_geometry_gives_the_pair_torques_and_no_net_force():
    layout = thesis_layout()
    assert len(layout) == 16 and sum(role == "axial" for *_, role in layout) == 4
    # every RCS thruster on the centre of an edge of the module (x in [-0.15, -0.05], |y|, |z| <= 0.05)
    for _, (x, y, z), d, role in layout:
        assert -0.15 <= x <= -0.05 and abs(y) <= 0.05 and abs(z) <= 0.05
        assert math.isclose(np.linalg.norm(d), 1.0)
        if role != "axial":
            assert sum(abs(v) in (0.05,) for v in (y, z)) + (x in (-0.15, -0.05)) == 2  # on an edge
    s = ThrusterSet()
    levels = tc.pair_torques()
    for axis in range(3):
        for sign in (1, -1):
            flags = [0, 0, 0]
            flags[axis] = sign
            force, torque = s.force_and_torque(flags)
            expected = [0.0, 0.0, 0.0]
            expected[axis] = sign * levels[axis]
            assert torque == tuple(expected)  # bit for bit: the thesis cases do not move
            assert force == (0.0, 0.0, 0.0)
    assert s.force_and_torque([0, 0, 0], axial=True) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


def test_same_firing_and_propellant_as_the_pair_model():
    pairs, single = ThrusterPairs(), ThrusterSet()
    rng = np.random.default_rng(3)
    for _ in range(400):
        cmd = rng.uniform(-0.004, 0.004, 3)
        assert single.flags(cmd) == pairs.flags(cmd)
        assert single.force_and_torque(single.flags(cmd))[1] == pytest.approx(pairs.applied_torque(cmd), abs=1e-18)
        pairs.step(cmd, 0.015)
        single.step(single.flags(cmd), 0.015)
    assert single.axis_fire_time() == pytest.approx(pairs.fire_time, rel=1e-12)
    assert single.propellant_mass() == pytest.approx(pairs.propellant_mass(), rel=1e-12)


def test_misalignment_and_force_error_leave_a_net_force_and_cross_torques():
    angle = math.radians(1.0)
    # the same tilt of a pair's two opposite thrusters cancels in the force: tilt them apart
    s = ThrusterSet(misalignment=[(angle * (-1) ** i, 0.0) for i in range(16)], force_error=[0.02] * 16)
    force, torque = s.force_and_torque([0, 1, 0])
    assert 0.0 < np.linalg.norm(force) <= 2 * 0.025 * 1.02 * math.sin(angle) + 1e-12
    assert abs(torque[1]) == pytest.approx(tc.pair_torques()[1] * 1.02, rel=1e-3)
    assert max(abs(torque[0]), abs(torque[2])) > 0.0  # cross-axis torque from the tilt
    # the four axial thrusters tilted alike: the burn's disturbance torque, (sum of l) x F
    _, burn = ThrusterSet(misalignment=[(angle, 0.0)] * 16).force_and_torque([0, 0, 0], axial=True)
    assert np.linalg.norm(burn) == pytest.approx(4 * 0.025 * 0.15 * math.sin(angle), rel=1e-6)
    with pytest.raises(ValueError, match="misalignment must be 16 pairs"):
        ThrusterSet(misalignment=[(0.3, 0.0)] * 16)
    with pytest.raises(ValueError, match="force_error must be 16"):
        ThrusterSet(force_error=[0.0] * 3)


def test_minimum_on_time_holds_a_firing():
    s = ThrusterSet(min_on_time=0.05)
    s.step([1, 0, 0], 0.015)
    for _ in range(3):  # the command is gone, the thrusters finish their 50 ms
        assert s.force_and_torque([0, 0, 0])[1][0] > 0.0
        s.step([0, 0, 0], 0.015)
    assert s.force_and_torque([0, 0, 0])[1] == (0.0, 0.0, 0.0)
    assert s.axis_fire_time()[0] == pytest.approx(0.06)
    s.set_state(ThrusterSet().get_state())
    assert s.propellant_mass() == 0.0


def test_off_pulsing_gives_y_and_z_torque_from_the_axial_thrusters():
    levels = tc.pair_torques()
    plain, pulsing = ThrusterSet(), ThrusterSet(off_pulsing=True)
    for flags in ([0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [1, 1, -1], [0, 0, 0]):
        assert pulsing.force_and_torque(flags) == plain.force_and_torque(flags)  # outside the burn: RCS pairs
    for axis in (1, 2):
        for sign in (1, -1):
            flags = [0, 0, 0]
            flags[axis] = sign
            off = pulsing.axial_off(flags, axial=True)
            assert len(off) == 2
            force, torque = pulsing.force_and_torque(flags, axial=True)
            expected = [0.0, 0.0, 0.0]
            expected[axis] = sign * levels[axis]  # a F = F c/3 for the thesis' a = c/3
            assert torque == pytest.approx(expected, abs=1e-15)
            assert force == (0.0, 0.0, 0.0)  # no RCS thruster fires
    # both axes: the one diagonal thruster, half the level on each; x still from its pair
    assert len(pulsing.axial_off([1, 1, -1], axial=True)) == 1
    _, torque = pulsing.force_and_torque([1, 1, -1], axial=True)
    assert torque == pytest.approx([levels[0], 0.5 * levels[1], -0.5 * levels[2]], abs=1e-15)
    # the thrust lost is counted in thruster-seconds, no RCS propellant for y and z
    pulsing.step([0, 1, 0], 0.015, axial=True)
    pulsing.step([0, 1, 1], 0.015, axial=True)
    pulsing.step([0, 1, 0], 0.015, axial=False)  # outside the burn: the y pair fires
    assert pulsing.axial_off_time == pytest.approx(3 * 0.015)
    assert pulsing.axis_fire_time() == pytest.approx([0.0, 0.015, 0.0])
    restored = ThrusterSet(off_pulsing=True)
    restored.set_state(pulsing.get_state())
    assert restored.axial_off_time == pulsing.axial_off_time


def test_off_pulsing_cancels_a_tilted_thrust_axis_without_rcs_propellant():
    """The burn's misalignment torque about y trimmed by switching axial thrusters off for part of
    the time: the same torque on average as the RCS pair's, no RCS propellant."""
    tilt = math.radians(1.0)
    kwargs = {"misalignment": [(0.0, 0.0)] * 12 + [(tilt, 0.0)] * 4}
    disturbance = ThrusterSet(**kwargs).force_and_torque([0, 0, 0], axial=True)[1]
    axis = int(np.argmax(np.abs(disturbance)))
    assert axis in (1, 2)
    flags = [0, 0, 0]
    flags[axis] = -int(np.sign(disturbance[axis]))
    for pulsing in (False, True):
        s = ThrusterSet(off_pulsing=pulsing, **kwargs)
        on = s.force_and_torque(flags, axial=True)[1][axis]
        duty = -disturbance[axis] / (on - disturbance[axis])  # fraction of the time at `flags` for zero mean
        assert 0.0 < duty < 0.2
        s.step(flags, duty * 100.0, axial=True)
        s.step([0, 0, 0], (1 - duty) * 100.0, axial=True)
        if pulsing:
            assert s.propellant_mass() == 0.0 and s.axial_off_time == pytest.approx(2 * duty * 100.0)
        else:
            assert s.propellant_mass() > 0.0 and s.axial_off_time == 0.0


def test_the_allocation_over_every_thruster_is_the_pairs():
    """The allocation the fault management falls back to gives, with nothing excluded, exactly the
    thesis' pairs for every flag triple (its costs rank them first)."""
    s = ThrusterSet()
    table = allocation_table(s.nominal_torques, s.nominal_forces, s.levels, s.force, s.rcs)
    for flags, thrusters in table.items():
        assert sorted(thrusters) == s.commanded(list(flags)), flags


@pytest.mark.parametrize("dead", range(12))
def test_a_disabled_thruster_never_fires_and_the_others_take_its_axis(dead):
    """Any one RCS thruster's valve closed: every single-axis command still gives a torque of the
    commanded sign on its axis (at least half a pair's), the side torques within half a pair's."""
    s = ThrusterSet()
    s.disable(dead)
    levels = s.levels
    for axis in range(3):
        for sign in (1, -1):
            flags = [0, 0, 0]
            flags[axis] = sign
            assert dead not in s.commanded(flags) and dead not in s.firing(flags)
            _, torque = s.force_and_torque(flags)
            assert sign * torque[axis] >= 0.5 * levels[axis] - 1e-15, (s.layout[dead][0], flags, torque)
            for other in set(range(3)) - {axis}:
                assert abs(torque[other]) <= 0.5 * levels[other] + 1e-15, (s.layout[dead][0], flags, torque)
    assert s.commanded([0, 0, 0]) == []
    restored = ThrusterSet()
    restored.set_state(s.get_state())
    assert restored.disabled == {dead} and restored.commanded([1, -1, 1]) == s.commanded([1, -1, 1])


@pytest.mark.parametrize("dead", range(12))
def test_in_the_burn_a_disabled_thruster_leaves_the_side_torque_to_the_axial_thrusters(dead):
    """In the burn with off-pulsing an x flag opens only what gives x: with an x thruster closed its
    partner alone (half the torque, its side torque to the off-pulsing), never a y pair beside it;
    with any other closed, the x pair as before. Reopened, the pairs again."""
    s = ThrusterSet(off_pulsing=True)
    s.disable(dead)
    name = s.layout[dead][0]
    for sign in (1, -1):
        opened = s.commanded([sign, 1, -1], axial=True)
        pair = ThrusterSet(off_pulsing=True).commanded([sign, 0, 0], axial=True)
        if dead in pair:
            assert opened == [i for i in pair if i != dead], (name, opened)
        else:
            assert opened == pair, (name, opened)
        _, torque = s.force_and_torque([sign, 0, 0], axial=True)
        assert sign * torque[0] >= 0.5 * s.levels[0] - 1e-15
    s.enable(dead)
    assert s.commanded([1, 1, -1], axial=True) == ThrusterSet(off_pulsing=True).commanded([1, 1, -1], axial=True)
    assert s.commanded([1, 1, -1]) == ThrusterSet().commanded([1, 1, -1]) and not s.disabled


def test_a_stuck_thruster_from_its_time_on_and_its_valve_closed():
    names = [name for name, *_ in thesis_layout()]
    off = ThrusterSet(stuck_thruster=1, stuck_time=0.03)  # x+1 stuck off after 30 ms of operation
    on = ThrusterSet(stuck_thruster=5, stuck_on=True, stuck_time=0.03)  # y+far stuck open
    x1, y_far = names.index("x+1"), names.index("y+far")
    for s in (off, on):
        s.step([0, 0, 0], 0.015)
        assert s.stuck is None and s.firing([1, 0, 0]) == s.commanded([1, 0, 0])
        s.step([1, 0, 0], 0.015)
    assert off.stuck == x1 and off.firing([1, 0, 0]) == [i for i in off.commanded([1, 0, 0]) if i != x1]
    assert on.stuck == y_far and on.firing([0, 0, 0]) == [y_far]
    # the open valve's torque and force act without a command; the propellant is counted
    force, torque = on.force_and_torque([0, 0, 0])
    assert torque == pytest.approx(on.torques[y_far]) and force == pytest.approx(on.forces[y_far])
    spent = on.propellant_mass()
    on.step([0, 0, 0], 1.0)
    assert on.propellant_mass() > spent
    on.disable(y_far)  # the latch valve closed: it stops
    # stuck open from the start of its operation: it vents from the set's first step, not before
    # (in the mission's determination the set does not step, and nothing would watch that torque)
    early = ThrusterSet(stuck_thruster=5, stuck_on=True, stuck_time=0.0)
    assert early.stuck == y_far and early.firing([0, 0, 0]) == [] and early.force_and_torque([0, 0, 0])[1] == (0.0,) * 3
    early.step([0, 0, 0], 0.015)
    assert early.firing([0, 0, 0]) == [y_far] and early.fire_time[y_far] == 0.0
    early.step([0, 0, 0], 0.015)
    assert early.fire_time[y_far] == pytest.approx(0.015)
    assert on.firing([0, 0, 0]) == [] and y_far not in on.firing([0, 1, 0])
    with pytest.raises(ValueError, match="stuck_thruster = 13 must be 0"):
        ThrusterSet(stuck_thruster=13)
    with pytest.raises(ValueError, match="stuck_time"):
        ThrusterSet(stuck_thruster=1, stuck_time=-1.0)
    with pytest.raises(ValueError, match="not one of the RCS thrusters"):
        ThrusterSet().disable(12)  # an axial thruster
