"""The reaction-wheel array, its torque distribution and the MRP law on their own (their Basilisk
comparisons are in test_wheels_vs_basilisk.py): the physics a wheel array must keep whatever the
reference (momentum exchanged with the body, friction, limits, the null space) and the errors a
user's bad values get."""
import math

import numpy as np
import pytest

from components.acs import reaction_wheel_array as rwa
from components.acs.wheel_torque_distribution import WheelTorqueDistribution
from components.attitude.mrp_feedback import MrpFeedback
from components.attitude.rigid_body import RigidBody
from components.core import rotations
from components.mission import cubesat_3u
from system_ssp.systems.generators import cubesat_3u as cubesat_3u_system

AXES = np.array(cubesat_3u_system.WHEEL_AXES)  # the shipped system's
J = [cubesat_3u.WHEELS.J_s] * 4
SPACECRAFT = np.array(cubesat_3u.SPACECRAFT.inertia_B)


def _array(**kwargs):
    values = dict(axes=AXES, inertias=J, max_torque=[1e-3] * 4, max_speed=[600.0] * 4)
    values.update(kwargs)
    return rwa.ReactionWheelArray(**values)


def _total_momentum_N(body, wheels):
    A = np.array(rotations.attitude_matrix(body.q))
    return A.T @ (np.array(body.J) @ np.array(body.omega) + wheels.momentum_B())


def test_wheels_and_body_exchange_momentum_without_losing_any():
    """A tumbling 3U whose wheels spin up and down against Coulomb and viscous friction, no external
    torque: the total angular momentum in N stays put (to the RK4 truncation of one 0.1 s sub-step
    per step at up to 4 deg/s, 3e-8 of it over 600 s; it falls as h^4), while the wheels' part
    changes by more than the total."""
    wheels = _array(coulomb=[2e-5] * 4, viscous=[5e-8] * 4, speed0=[300.0, -200.0, 100.0, 0.0])
    body = RigidBody(rwa.body_inertia(SPACECRAFT, AXES, J), cubesat_3u.INITIAL_ATTITUDE, cubesat_3u.INITIAL_RATE,
                     max_substep=0.1)
    wheels.start(body.omega)
    H0 = _total_momentum_N(body, wheels)
    h_w0 = wheels.momentum_B().copy()
    for k in range(6000):
        command = 1e-4 * np.sin(0.002 * k + np.arange(4))
        _, _, _, torque_B, momentum_B, _ = wheels.evaluate(command)
        body.step((0.0, 0.0, 0.0), 0.1, tuple(torque_B), tuple(momentum_B))
        wheels.step(command, 0.1, body.omega)
    drift = np.linalg.norm(_total_momentum_N(body, wheels) - H0) / np.linalg.norm(H0)
    assert drift < 1e-7, drift
    assert np.linalg.norm(wheels.momentum_B() - h_w0) > np.linalg.norm(H0)


def test_friction_spins_a_free_wheel_down_as_the_exact_solution():
    """Viscous friction alone on a wheel of a body held at rest: Omega decays as exp(-c t / J);
    holding the friction over each 0.01 s step gives (1 - c h / J)^n, within 3e-5 of it."""
    c, w0 = 1e-7, 500.0
    wheels = _array(viscous=[c] * 4, speed0=[w0, 0.0, 0.0, 0.0])
    wheels.start((0.0, 0.0, 0.0))
    for _ in range(10000):
        wheels.step(np.zeros(4), 0.01, (0.0, 0.0, 0.0))
    assert wheels.speeds()[0] == pytest.approx(w0 * (1.0 - c * 0.01 / J[0]) ** 10000, rel=1e-12)
    assert wheels.speeds()[0] == pytest.approx(w0 * math.exp(-c * 100.0 / J[0]), rel=3e-5)
    assert wheels.speeds()[0] < 0.6 * w0


def test_command_limits_power_and_speed():
    wheels = _array(max_power=[0.1] * 4, min_torque=[1e-5] * 4, speed0=[600.0, 300.0, -300.0, 10.0],
                    base_power=[0.05] * 4, motor_efficiency=0.8)
    wheels.start((0.0, 0.0, 0.0))
    speeds, u, _, _, _, power = wheels.evaluate([1e-3, 1e-3, 5e-6, -2e-3])
    assert u[0] == 0.0  # at max speed: nothing that speeds it up
    assert u[1] == pytest.approx(0.1 / 300.0)  # power limit: |u Omega| = 0.1 W
    assert u[2] == 0.0  # below the minimum torque
    assert u[3] == -1e-3  # saturated
    assert power[1] == pytest.approx(0.05 + 0.1 / 0.8)
    assert power[3] == pytest.approx(0.05)  # braking: the energy is dumped (regen_efficiency 0)
    assert wheels.evaluate([-1e-3, 0, 0, 0])[1][0] == pytest.approx(-0.1 / 600.0)  # it can still slow down


def test_distribution_gives_the_commanded_body_torque_and_the_null_space_none():
    """Minimum norm over the available wheels (one failed): the body feels exactly the command;
    the null-space torques drive the speeds toward the desired ones and add no body torque."""
    distribution = WheelTorqueDistribution(AXES, null_space_gain=1e-6, desired_speeds=[100.0] * 4)
    torque = np.array([2e-4, -1e-4, 3e-4])
    for available in ([True] * 4, [True, False, True, True]):
        minimum, total = distribution.motor_torques(torque, np.array([300.0, -50.0, 20.0, 0.0]), available)
        assert np.allclose(-AXES.T @ minimum, torque, rtol=0, atol=1e-18)
        assert minimum[~np.array(available)].tolist() in ([], [0.0])
    minimum, total = distribution.motor_torques(torque, np.array([300.0, -50.0, 20.0, 0.0]))
    null = total - minimum
    assert np.allclose(AXES.T @ null, 0.0, atol=1e-18)
    assert null @ (np.array([300.0, -50.0, 20.0, 0.0]) - 100.0) < 0.0  # toward the desired speeds


def test_mrp_feedback_integral_stays_within_its_limit():
    law = MrpFeedback(SPACECRAFT, 0.015, 0.06, Ki=0.01, integral_limit=1e-3)
    for _ in range(1000):
        law.torque((0.3, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        law.step((0.3, 0.0, 0.0), 0.1)
    assert law.int_sigma[0] == pytest.approx(1e-3)


@pytest.mark.parametrize("kwargs, message", [
    (dict(axes=[(1, 0, 0)] * 7, inertias=[1e-5] * 7, max_torque=[1e-3] * 7, max_speed=[600.0] * 7),
     "wheel_count = 7 must be in 1..6"),
    (dict(axes=[(1, 0, 0), (0, 0, 0)], inertias=[1e-5] * 2, max_torque=[1e-3] * 2, max_speed=[600.0] * 2),
     "spin axis 2 is zero"),
    (dict(axes=[(1, 0, 0)], inertias=[0.0], max_torque=[1e-3], max_speed=[600.0]),
     "J_s of wheel 1 = 0.0 kg.m2 must be a finite number > 0"),
    (dict(axes=[(1, 0, 0)], inertias=[1e-5], max_torque=[1e-3], max_speed=[600.0], speed0=[700.0]),
     "Omega0 of wheel 1 = 700.0 rad/s must be within +-max_speed"),
])
def test_bad_values_name_the_wheel_and_what_is_allowed(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("+", r"\+").replace(".", r"\.")):
        rwa.ReactionWheelArray(**kwargs)


def test_an_array_used_before_its_start_says_so():
    with pytest.raises(RuntimeError, match=r"start\(omega_BN_B\)"):
        _array().speeds()
