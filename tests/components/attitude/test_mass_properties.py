"""Mass properties that follow the propellant drawn (issue 28, item 4): the inertia and centre of
mass of the body the tank empties from, the rigid body's dynamics with them, the thrusters' torques
about the moving centre of mass and their force beyond the propulsion's thrust, which the orbit
takes as a running total of impulse."""
import itertools
import math

import numpy as np
import pytest

from components.attitude import mass_properties, rigid_body
from components.attitude.thruster_set import ThrusterSet
from components.orbit.cowell import CowellOrbit
from components.orbit.propulsion import ImpulseWindow

A, B, C = 0.1, 0.2, 0.3
TANK = mass_properties.tank_position(A, C)


def _point_masses(mass, n=24):
    """A uniform box of `mass` (edges c along x, a along y, b along z) as n^3 equal point masses at
    the centres of its cells."""
    cells = [(np.arange(n) + 0.5) / n - 0.5]
    xs, ys, zs = np.meshgrid(cells[0] * C, cells[0] * A, cells[0] * B, indexing="ij")
    points = np.stack([xs.ravel(), ys.ravel(), zs.ravel()], axis=1)
    return points, np.full(len(points), mass / len(points))


def _inertia_about_centre(points, masses):
    m = masses.sum()
    com = (masses[:, None] * points).sum(axis=0) / m
    r = points - com
    J = sum(w * (np.dot(p, p) * np.eye(3) - np.outer(p, p)) for p, w in zip(r, masses))
    return J, com


def test_drawn_propellant_matches_summing_the_point_masses():
    """The formula (point mass removed at the tank, parallel axes to the new centre of mass) against
    the inertia summed over a body of point masses with the propellant taken out at the tank."""
    points, masses = _point_masses(12.0)
    J0, com0 = _inertia_about_centre(points, masses)
    assert np.allclose(com0, 0.0, atol=1e-15)
    for dm in (0.0, 0.5641, 1.7):
        J, com = mass_properties.drawn(J0.tolist(), 12.0, dm, TANK)
        J_sum, com_sum = _inertia_about_centre(np.vstack([points, [TANK]]), np.append(masses, -dm))
        assert np.allclose(com, com_sum, rtol=0, atol=1e-15)
        assert np.allclose(J, J_sum, rtol=1e-12, atol=1e-15)
    # the 420 km burn: the centre of mass 4.9 mm to +x, the y and z moments 4.5 % and 5.9 % down,
    # the x moment (the tank on the x axis) unchanged
    J0 = rigid_body.box_inertia(12.0, A, B, C)
    J, com = mass_properties.drawn(J0.tolist(), 12.0, 0.5641, TANK)
    assert com[0] == pytest.approx(0.5641 * 0.1 / (12.0 - 0.5641)) and com[1:] == (0.0, 0.0)
    assert J[0][0] == J0[0, 0]
    assert 1.0 - J[1][1] / J0[1, 1] == pytest.approx(0.0451, abs=1e-3)
    assert 1.0 - J[2][2] / J0[2, 2] == pytest.approx(0.0587, abs=1e-3)


@pytest.mark.parametrize("dm", [-1e-3, 12.0, math.nan])
def test_drawn_propellant_outside_the_body_is_refused(dm):
    with pytest.raises(ValueError, match="propellant drawn"):
        mass_properties.drawn(rigid_body.box_inertia(12.0, A, B, C).tolist(), 12.0, dm, TANK)


def test_moment_errors_scale_the_body_along_its_axes():
    """with_moment_errors against bodies of point masses whose coordinates are stretched by
    sqrt(1 + e_i) along each axis (which scales their second moments by 1 + e_i): a box (the
    analytic box of stretched edges) and a lopsided cloud with products of inertia."""
    e = (0.1, -0.1, 0.07)
    stretch = np.sqrt(1.0 + np.array(e))
    J = mass_properties.with_moment_errors(rigid_body.box_inertia(12.0, A, B, C), e)
    # edge c along x, a along y, b along z
    box = rigid_body.box_inertia(12.0, A * stretch[1], B * stretch[2], C * stretch[0])
    assert np.allclose(J, box, rtol=1e-13, atol=0.0)
    rng = np.random.default_rng(4)
    points = rng.normal(size=(60, 3)) * (0.15, 0.05, 0.1) + (0.02, -0.01, 0.03)
    masses = rng.uniform(0.1, 0.3, 60)
    J0, _ = _inertia_about_centre(points, masses)
    assert abs(J0[0, 1]) > 1e-4  # products of inertia present
    J1, _ = _inertia_about_centre(points * stretch, masses)
    assert np.allclose(mass_properties.with_moment_errors(J0.tolist(), e), J1, rtol=1e-12, atol=1e-15)


def test_moment_errors_keep_a_real_body_where_moment_errors_would_not():
    """Errors of 10 % on the box's moments themselves could break the triangle inequality (0.13 <=
    0.05 + 0.10 is 0.02 from its edge): the second moments' errors never do, and move each moment by
    at most 10 %; zero errors give the nominal inertia itself, bit for bit."""
    J0 = rigid_body.box_inertia(12.0, A, B, C)
    d = np.diag(J0)
    assert d[1] * 1.1 > d[0] * 0.9 + d[2] * 0.9  # the moments themselves, off by 10 %: no body
    for e in itertools.product((-0.1, 0.0, 0.1), repeat=3):
        J = np.array(mass_properties.with_moment_errors(J0, e))
        rigid_body.check_inertia(J)  # a real body
        assert np.all(np.abs(np.diag(J) / d - 1.0) <= 0.1 + 1e-12)
    nominal = mass_properties.with_moment_errors(J0, (0.0, 0.0, 0.0))
    assert nominal == tuple(tuple(float(x) for x in row) for row in J0)
    for bad in ((0.6, 0.0, 0.0), (0.0, math.nan, 0.0), (0.1, 0.1)):
        with pytest.raises(ValueError, match="inertia errors"):
            mass_properties.with_moment_errors(J0, bad)


def test_inverse_of_a_full_inertia():
    J = ((0.05, 0.001, -0.002), (0.001, 0.13, 0.003), (-0.002, 0.003, 0.1))
    assert np.allclose(np.array(mass_properties.inverse(J)) @ np.array(J), np.eye(3), rtol=0, atol=1e-13)
    with pytest.raises(ValueError, match="positive definite"):
        mass_properties.inverse(((1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))


def test_rigid_body_turns_faster_as_the_tank_empties():
    """A y torque held for one step: the rate gained grows as the y moment falls; the body's state
    (inertia included) survives get/set state; below the resolution nothing is recomputed."""
    J0 = rigid_body.box_inertia(12.0, A, B, C)
    full, drained = rigid_body.RigidBody(J0), rigid_body.RigidBody(J0)
    drained.follow_propellant(mass_properties.RESOLUTION / 2, 12.0, TANK)
    assert drained.J == full.J and drained.drawn == 0.0
    drained.follow_propellant(0.5641, 12.0, TANK)
    J, com = mass_properties.drawn(J0.tolist(), 12.0, 0.5641, TANK)
    assert drained.J == J and drained.center_of_mass == com
    torque = (0.0, 2.5e-3, 0.0)
    for body in (full, drained):
        body.step(torque, 0.015)
    assert drained.omega[1] / full.omega[1] == pytest.approx(J0[1, 1] / J[1][1], rel=1e-9)
    copy = rigid_body.RigidBody(J0)
    copy.set_state(drained.get_state())
    for body in (copy, drained):
        body.step(torque, 0.015)
    assert copy.omega == drained.omega and copy.q == drained.q


def test_thruster_torques_about_the_moving_centre_of_mass():
    """A pair is a couple: its torque is the same about any point, bit for bit. The net force of
    the thrusters firing (misaligned axial thrusters in the burn, a lone thruster) adds -r_cm x F."""
    angles = [(0.01 * (i % 3 - 1), -0.008 * (i % 2)) for i in range(16)]
    errors = [0.03 * ((i * 7) % 5 - 2) / 2 for i in range(16)]
    fixed = ThrusterSet(force_error=errors, misalignment=angles)
    moving = ThrusterSet(force_error=errors, misalignment=angles)
    moving.follow_propellant(12.0, TANK)
    moving.set_main_propellant(0.5641)
    com = moving.center_of_mass
    assert com[0] == pytest.approx(0.5641 * 0.1 / (12.0 - 0.5641))
    aligned, aligned_moving = ThrusterSet(), ThrusterSet()
    aligned_moving.follow_propellant(12.0, TANK)
    aligned_moving.set_main_propellant(0.5641)
    for flags in itertools.product((-1, 0, 1), repeat=3):
        assert aligned_moving.force_and_torque(flags) == aligned.force_and_torque(flags)
        for burn in (False, True):
            f0, t0 = fixed.force_and_torque(flags, burn)
            f1, t1 = moving.force_and_torque(flags, burn)
            assert f1 == f0
            net = np.array(f0) + sum((np.array(fixed.forces[i]) for i in fixed.axial_on(flags, burn)), np.zeros(3))
            assert np.allclose(np.array(t1) - t0, -np.cross(com, net), rtol=0, atol=1e-17)


def test_thrusters_impulse_beyond_the_propulsions_thrust():
    """The running total: the RCS net force of each step, and in the burn the axial thrusters' real
    force less their nominal n F x (which the propulsion gives the orbit)."""
    angles = [(0.0, 0.0)] * 12 + [(0.01, -0.005), (0.0, 0.01), (-0.01, 0.0), (0.004, 0.004)]
    errors = [0.02] * 12 + [0.05, -0.03, 0.0, 0.01]
    s = ThrusterSet(force_error=errors, misalignment=angles)
    assert ThrusterSet().impulse == (0.0, 0.0, 0.0)
    s.step((1, 0, 0), 0.015)  # an x pair: 2 % strong both, opposite: no net force
    assert np.allclose(s.impulse, 0.0, rtol=0, atol=1e-18)
    s.step((0, 0, 0), 0.5, axial=True)  # the burn, no RCS
    real = sum(np.array(s.forces[i]) for i in s.axial)
    nominal = sum(np.array(s.nominal_forces[i]) for i in s.axial)
    assert np.allclose(s.impulse, (real - nominal) * 0.5, rtol=1e-12, atol=1e-18)
    assert abs(s.impulse[0]) > 0 and abs(s.impulse[1]) > 0
    restored = ThrusterSet(force_error=errors, misalignment=angles)
    restored.set_state(s.get_state())
    assert restored.impulse == s.impulse


def test_impulse_window_gives_the_previous_steps_mean_force():
    w = ImpulseWindow()
    assert w.force((1.0, 2.0, 3.0), 0.5) == (0.0, 0.0, 0.0)  # the first step only sets the start
    assert w.force((1.5, 2.0, 2.0), 0.25) == (1.0, 0.0, -2.0)  # 0.5 N.s, -1 N.s over 0.5 s
    assert w.force((1.5, 2.5, 2.0), 1.0) == (0.0, 2.0, 0.0)  # over 0.25 s
    copy = ImpulseWindow()
    copy.set_state(w.get_state())
    assert copy.force((2.5, 2.5, 2.0), 1.0) == w.force((2.5, 2.5, 2.0), 1.0) == (1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="impulse_B"):
        w.force((1.0, math.inf, 0.0), 1.0)


def test_orbit_takes_the_mean_force_with_the_thrust():
    """The Cowell orbit fed a running total of impulse flies as one fed that mean force in F_thrust_B
    one step late; retrograde thrust (the thesis' option) takes the propulsion's alone."""
    q = (0.1, -0.2, 0.05, math.sqrt(1 - 0.01 - 0.04 - 0.0025))
    totals = [(0.0, 0.0, 0.0), (0.002, -0.001, 0.0005), (0.003, -0.001, 0.0015), (0.003, 0.0, 0.0015)]
    fed, explicit = CowellOrbit(drag=False), CowellOrbit(drag=False)
    t, h, previous = 0.0, 0.5, None
    for total in totals:
        extra = (0.0, 0.0, 0.0) if previous is None else tuple((a - b) / h for a, b in zip(total, previous))
        fed.set_inputs((0.1, 0.0, 0.0), q, False, 11.5, total, h)
        explicit.set_inputs(tuple(f + e for f, e in zip((0.1, 0.0, 0.0), extra)), q, False, 11.5)
        t += h
        fed.advance_to(t)
        explicit.advance_to(t)
        assert fed.outputs()["r_BN_N"] == explicit.outputs()["r_BN_N"]
        previous = total
    retro_fed, retro = CowellOrbit(drag=False), CowellOrbit(drag=False)
    for orbit, total in ((retro_fed, (0.0, 1.0, 0.0)), (retro, None)):
        orbit.set_inputs((0.1, 0.0, 0.0), q, True, 11.5, total, 0.5)
        orbit.advance_to(0.5)
        orbit.set_inputs((0.1, 0.0, 0.0), q, True, 11.5, None if total is None else (0.0, 3.0, 0.0), 0.5)
        orbit.advance_to(1.0)
    assert retro_fed.outputs()["r_BN_N"] == retro.outputs()["r_BN_N"]
