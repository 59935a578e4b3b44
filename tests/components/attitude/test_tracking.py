"""De-orbit attitude tracking (thesis 3.3.8, Eq. 67-73, Appendix C `Deorbit` /
`TargetQuaternion`, Appendix F): the component over the whole 420 km burn against the thesis'
attitude-control propellant, the desired-quaternion propagation, bad gains, and the FMU through
FMPy (declarations, state, a short closed loop with RigidBody against the component loop)."""
import math

import numpy as np
import pytest

from components.attitude import deorbit_tracking as dtr
from components.attitude import rigid_body, thrusters
from components.core import constants, jit, rotations
from fmu_helpers import check_declarations, instantiate

J_BOX = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3)  # Appendix A
H = 0.015  # Appendix A t_step
# Eq. 69: the end state of slew validation case 1, where Appendix F starts (q not normalized)
Q0 = (0.00017, 0.00041, 0.00043, 1.00060)
W0 = tuple(math.radians(x) for x in (-0.0053, -0.0054, -0.0021))
BURN_420KM = 38.74 * 60.0  # s, thesis 3.3.8
MP_THESIS = 4.75e-3  # kg, thesis 3.3.9


def test_tracking_rate_eq_67_68():
    T = dtr.orbit_period(constants.R_EQ + 400e3)
    assert T / 60.0 == pytest.approx(92.56, abs=0.005)
    assert math.degrees(dtr.tracking_rate()) == pytest.approx(0.0648, abs=5e-5)
    assert dtr.default_omega_d() == (0.0, 2 * math.pi / T, 0.0)


def test_target_quaternion_turns_at_omega_d():
    """TargetQuaternion (explicit Euler of q_dot = 1/2 Xi(q) w) follows the exact rotation
    q_d(t) = q(y, w t) (x) q_d0 to first order in w h; no normalization, as the script."""
    q0 = rotations.from_euler123(0.3, -0.2, 1.0)
    c = dtr.DeorbitTrackingController(J_BOX, q_d0=q0)
    w = c.omega_d[1]
    n = 10000
    for _ in range(n):
        c.advance(1.0, (0.0, 0.0, 0.0, 1.0))  # the measured q is ignored when q_d0 is given
    exact = rotations.circle_cross(rotations.from_axis_angle((0, 1, 0), w * n), q0)
    unit = rotations.normalized(c.q_d)
    assert max(abs(a - b) for a, b in zip(unit, exact)) < 1e-6  # phase error O(n (w h)^3)
    assert rotations.norm(c.q_d) - 1.0 == pytest.approx(n * (0.5 * w) ** 2 / 2, rel=1e-3)  # Euler's drift
    # with q_d0 given the target is propagated even while disabled
    before = c.q_d
    c.advance(1.0, (0.0, 0.0, 0.0, 1.0), enabled=False)
    assert c.q_d != before


def test_latch_from_measured_q_and_release_when_disabled():
    c = dtr.DeorbitTrackingController(J_BOX)
    q = rotations.from_euler123(0.1, 0.2, 0.3)
    assert c.q_d is None and c.target(q) == q and c.attitude_error(q) == 0.0
    assert c.command(q, c.omega_d) == ([0.0, 0.0, 0.0], [0, 0, 0])  # on the surface: s = 0
    assert c.command(q, (0.0, 0.0, 0.0))[1] == [0, 1, 0]  # at rest: spin up about y
    c.advance(H, q)
    step = rotations.from_axis_angle((0, 1, 0), c.omega_d[1] * H)
    assert c.q_d == pytest.approx(rotations.circle_cross(step, q), abs=1e-10)
    state = c.get_state()
    c.advance(H, q, enabled=False)
    assert c.q_d is None
    c.set_state(state)
    assert c.q_d == pytest.approx(rotations.circle_cross(step, q), abs=1e-10)


def test_control_law_one_evaluation_by_hand():
    """Eq. 70-72 written out with numpy-free arithmetic, against an independent numpy form."""

    J = np.array([[0.05, 0.001, 0.0], [0.001, 0.13, 0.002], [0.0, 0.002, 0.10]])
    c = dtr.DeorbitTrackingController(J, k=0.7, G=(0.2, 0.1, 0.3), e=(0.002, 0.001, 0.0005),
                                      omega_d=(0.0001, 0.0011, -0.0002), omega_dot_d=(1e-5, 0.0, 2e-5),
                                      q_d0=rotations.from_euler123(0.01, -0.02, 0.005),
                                      torque_level=(1e-9, 1e-9, 1e-9))
    q = rotations.from_euler123(0.012, -0.019, 0.0052)
    w = np.array([0.0004, 0.0012, -0.0001])
    qd = np.array(c.q_d)
    dq = np.array(rotations.circle_cross(q, rotations.inverse(qd)))
    sg = np.sign(dq[3])
    s = (w - c.omega_d) + c.k * sg * dq[:3]
    e = np.array(c.e)
    sbar = np.where(s > e, 1.0, np.where(s < -e, -1.0, s / e))
    wd = np.array(c.omega_d)
    L = J @ (c.k / 2 * (abs(dq[3]) * (wd - w) - sg * np.cross(dq[:3], w + wd)) + np.array(c.omega_dot_d)
             - np.array(c.G) * sbar) + np.cross(w, J @ w)
    torque, flags, s_c, dq_c = c.evaluate(q, tuple(w))
    np.testing.assert_allclose(s_c, s, rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(dq_c, dq, rtol=1e-12, atol=1e-18)
    assert flags == [int(x) for x in np.sign(L)] and all(abs(x) > 1e-9 for x in L)
    assert any(abs(x) < 1 for x in s / e)  # the boundary layer s/e was exercised


def _burn(form="eq72", duration=BURN_420KM, h=H):
    """Appendix F loop: Deorbit -> StateChange (euler) -> TargetQuaternion, from Eq. 69."""
    body = rigid_body.RigidBody(J_BOX, Q0, W0, integrator="euler")
    ctl = dtr.DeorbitTrackingController(J_BOX, torque_form=form)
    rcs = thrusters.ThrusterPairs()  # Isp 42 s, g0 9.81, F 25 mN: mp = 2 F T_on / (Isp g0)
    worst_angle = worst_pointing = 0.0
    for _ in range(int(round(duration / h))):
        q = body.q
        torque, _ = ctl.command(q, body.omega)
        rcs.step(torque, h)
        body.step(torque, h)
        ctl.advance(h, q)
        worst_angle = max(worst_angle, ctl.attitude_error(body.q))
        worst_pointing = max(worst_pointing, ctl.pointing_error(body.q))
    return rcs, body, ctl, worst_angle, worst_pointing


def test_420km_burn_propellant_and_tracking():
    """Whole 38.74 min burn at 15 ms (154 960 steps). Thesis: 4.75 g; this model: 4.764 g
    (fire time x 10.94 s, y 19.32 s, z 9.00 s), tracking error at most 0.055 deg."""
    rcs, body, ctl, worst_angle, worst_pointing = _burn()
    mp = rcs.propellant_mass()
    assert mp == pytest.approx(MP_THESIS, rel=0.25)
    assert mp == pytest.approx(4.7637e-3, rel=1e-3)  # regression on this model's figure
    assert math.degrees(worst_angle) < 0.1
    assert math.degrees(worst_pointing) <= math.degrees(worst_angle) + 1e-12
    # turned with the burn direction: about 150.7 deg about y, at the desired rate
    turned = 2.0 * math.acos(min(1.0, abs(rotations.error_quaternion(body.q, Q0)[3]) / rotations.norm(body.q)))
    assert math.degrees(turned) == pytest.approx(math.degrees(ctl.omega_d[1] * BURN_420KM), abs=0.1)
    assert body.omega[1] == pytest.approx(ctl.omega_d[1], abs=math.radians(0.01))


def test_printed_script_precedence_chatters():
    """The Deorbit line as printed (I on the first term only) fires on most steps: over the
    first 60 s it uses far more propellant than Eq. 72 (see the module docstring)."""
    eq = _burn("eq72", 60.0)[0].total_fire_time()
    literal = _burn("script_literal", 60.0)[0].total_fire_time()
    assert literal > 10 * eq and literal > 30.0


def test_boundary_layer_sized_for_the_estimate():
    """e widens so that the law's deadband in s (e level / (J G)) covers 3 sigmas of the
    estimate's noise and one impulse bit; without the factors it is the thesis' fixed e."""
    thesis = dtr.DeorbitTrackingController(J_BOX)
    assert thesis.boundary_layer((0.01, 0.01, 0.01)) == (0.001, 0.001, 0.001) == thesis.e
    ctl = dtr.DeorbitTrackingController(J_BOX, knowledge_sigmas=3.0, impulse_bits=1.0, rate_sigma=1e-4)
    levels = [0.0025] * 3  # Eq. 16: one pair's torque about each axis
    assert ctl.levels == pytest.approx(levels, rel=1e-12)
    # one impulse bit, level h / J, is a deadband of e = h G = 1.5e-3 on every axis
    bits_only = dtr.DeorbitTrackingController(J_BOX, impulse_bits=1.0)
    assert bits_only.boundary_layer((0.0, 0.0, 0.0)) == pytest.approx((0.0015, 0.0015, 0.0015), rel=1e-12)
    for sigma in ((0.0, 0.0, 0.0), (1e-3, 2e-3, 5e-4)):
        by_hand = [max(0.001, 0.0015, 3 * math.hypot(1e-4, 0.5 * sigma[i]) * J_BOX[i, i] * 0.1 / levels[i])
                   for i in range(3)]
        assert ctl.boundary_layer(sigma) == pytest.approx(by_hand, rel=1e-12) and ctl.e == tuple(ctl.e)
    assert by_hand[1] > 0.005  # 2 mrad of attitude noise about y: a layer five times the thesis'
    # a rate error of 1e-3 rad/s about y: the thesis' layer fires a pair, the sized one does not
    wd = thesis.omega_d
    omega = (wd[0], wd[1] + 1e-3, wd[2])
    assert thesis.command(Q0, omega)[1][1] != 0 and ctl.command(Q0, omega)[1] == [0, 0, 0]
    with pytest.raises(ValueError, match="sigma_attitude .* must be three finite numbers >= 0"):
        ctl.boundary_layer((0.0, -1e-3, 0.0))
    # the layer is kept while the sigmas repeat (most steps): any sequence gives a fresh law's e
    for sigma in ((1e-3, 2e-3, 5e-4), (1e-3, 2e-3, 5e-4), (2e-3, 2e-3, 5e-4), (1e-3, 2e-3, 5e-4)):
        fresh = dtr.DeorbitTrackingController(J_BOX, knowledge_sigmas=3.0, impulse_bits=1.0, rate_sigma=1e-4)
        assert ctl.boundary_layer(sigma) == fresh.boundary_layer(sigma) == ctl.e
    with pytest.raises(ValueError, match="knowledge_sigmas = -1.0 must be a finite number >= 0"):
        dtr.DeorbitTrackingController(J_BOX, knowledge_sigmas=-1.0)


def test_sized_layer_does_not_fire_at_attitude_noise():
    """Two minutes of the burn on a noisy estimate (1 mrad per axis, white): the thesis' layer
    fires at the noise, the layer sized for it holds the attitude as well for a fraction of the
    firing."""
    rng = np.random.default_rng(7)
    noise = rng.normal(0.0, 1e-3, size=(8000, 3))
    result = {}
    for name, kwargs in (("thesis", {}), ("sized", {"knowledge_sigmas": 3.0, "impulse_bits": 1.0,
                                                    "rate_sigma": 1e-4})):
        body = rigid_body.RigidBody(J_BOX, Q0, W0, integrator="euler")
        ctl = dtr.DeorbitTrackingController(J_BOX, **kwargs)
        ctl.boundary_layer((1e-3, 1e-3, 1e-3))
        rcs = thrusters.ThrusterPairs()
        worst = 0.0
        for k in range(noise.shape[0]):
            angle = float(np.linalg.norm(noise[k]))
            q_est = tuple(float(x) for x in rotations.normalized(rotations.circle_cross(
                rotations.from_axis_angle(tuple(noise[k] / angle), angle), tuple(body.q))))
            torque, _ = ctl.command(q_est, body.omega)
            rcs.step(torque, H)
            body.step(torque, H)
            ctl.advance(H, q_est)
            if k > 2000:
                worst = max(worst, ctl.attitude_error(body.q))
        result[name] = (rcs.total_fire_time(), worst)
    assert result["sized"][0] < 0.25 * result["thesis"][0]
    assert math.degrees(result["sized"][1]) < 0.5


@pytest.mark.parametrize("kwargs, match", [
    ({"k": 0.0}, "k = 0.0 must be a finite positive"),
    ({"k": -1.0}, "k = -1.0"),
    ({"G": (0.1, 0.0, 0.1)}, "G .* must be three finite positive"),
    ({"G": (0.1, 0.1)}, "G "),
    ({"e": (0.001, -0.001, 0.001)}, "e .* must be three finite positive"),
    ({"e": (0.0, 0.001, 0.001)}, "saturation thresholds"),
    ({"omega_d": (0.0, float("nan"), 0.0)}, "omega_d"),
    ({"torque_level": (0.0025, 0.0, 0.0025)}, "torque_level"),
    ({"q_d0": (0.0, 0.0, 0.0, 0.0)}, "q_d0"),
    ({"torque_form": "other"}, "torque_form"),
    ({"inertia": [[1, 0, 0], [0, -1, 0], [0, 0, 1]]}, "positive definite"),
])
def test_bad_parameters_are_clear_errors(kwargs, match):
    args = {"inertia": J_BOX, **kwargs}
    with pytest.raises(ValueError, match=match):
        dtr.DeorbitTrackingController(**args)


# ---- FMU ------------------------------------------------------------------------------------
def test_fmu_declarations(build_one):
    deps = check_declarations(build_one("neighbor_tracking_controller.py"))
    q_in = [f"q_BN[{i}]" for i in (1, 2, 3, 4)]
    w_in = [f"omega_BN_B[{i}]" for i in (1, 2, 3)]
    target = [f"q_target_BN[{i}]" for i in (1, 2, 3, 4)] + [f"omega_target_B[{i}]" for i in (1, 2, 3)]
    sigma = [f"sigma_attitude_B[{i}]" for i in (1, 2, 3)]
    assert deps["torque_cmd_B[2]"] == sorted(q_in + w_in + target + sigma + ["enabled"])
    assert deps["thrust_flag[1]"] == sorted(q_in + w_in + target + sigma + ["enabled"])
    assert deps["done"] == sorted(q_in + w_in + target + sigma)
    assert deps["boundary_layer[2]"] == sigma
    assert deps["attitude_error"] == sorted(q_in + target) and deps["q_d[4]"] == sorted(q_in + target)
    assert deps["sliding_vector[3]"] == sorted(q_in + w_in + target + sigma)


def test_fmu_closed_loop_with_rigid_body_matches_component(build_one, tmp_path):
    """Tracking FMU and RigidBody FMU (euler), 15 ms steps, wired like the slew controller
    (thrusters' rounding passes the quantized command unchanged): bit-identical to the
    component loop; then disabling releases q_d and get/set FMU state restores it."""
    trk, tv = instantiate(build_one("neighbor_tracking_controller.py"), tmp_path, "tracking")
    body, bv = instantiate(build_one("neighbor_rigid_body.py"), tmp_path, "dynamics")
    q_out = [bv[f"q_BN[{i}]"] for i in (1, 2, 3, 4)]
    w_out = [bv[f"omega_BN_B[{i}]"] for i in (1, 2, 3)]
    q_in = [tv[f"q_BN[{i}]"] for i in (1, 2, 3, 4)]
    w_in = [tv[f"omega_BN_B[{i}]"] for i in (1, 2, 3)]
    cmd = [tv[f"torque_cmd_B[{i}]"] for i in (1, 2, 3)]
    qd_out = [tv[f"q_d[{i}]"] for i in (1, 2, 3, 4)]
    try:
        body.setString([bv["integrator"]], ["euler"])
        body.setReal([bv[f"q0[{i}]"] for i in (1, 2, 3, 4)] + [bv[f"omega0[{i}]"] for i in (1, 2, 3)],
                     list(Q0) + list(W0))
        for f in (trk, body):
            f.enterInitializationMode()
            f.exitInitializationMode()
        t = 0.0

        def advance(n):
            nonlocal t
            fired = 0
            for _ in range(n):
                trk.setReal(q_in + w_in, body.getReal(q_out + w_out))
                torque = trk.getReal(cmd)
                fired += sum(1 for x in torque if x)
                trk.doStep(t, H)
                body.setReal([bv[f"torque_B[{i}]"] for i in (1, 2, 3)], torque)
                body.doStep(t, H)
                t += H
            trk.setReal(q_in + w_in, body.getReal(q_out + w_out))
            return fired, body.getReal(q_out + w_out), trk.getReal(qd_out + [tv["attitude_error"]])

        n = 400
        fired, state, target = advance(n)
        ref_body = rigid_body.RigidBody(J_BOX, Q0, W0, integrator="euler")
        ref = dtr.DeorbitTrackingController(J_BOX)
        ref_fired = 0
        for _ in range(n):
            q = ref_body.q
            torque, _ = ref.command(q, ref_body.omega)
            ref_fired += sum(1 for x in torque if x)
            ref_body.step(torque, H)
            ref.advance(H, q)
        assert fired == ref_fired > 0
        assert state == list(ref_body.q) + list(ref_body.omega)
        assert target[:4] == list(ref.q_d)
        assert target[4] == ref.attitude_error(ref_body.q) < math.radians(0.1)

        saved = trk.getFMUstate()
        trk.setBoolean([tv["enabled"]], [False])
        trk.doStep(t, H)
        assert trk.getReal(cmd) == [0.0, 0.0, 0.0]
        assert trk.getReal(qd_out) == trk.getReal(q_in)  # released: q_d follows the measured q
        trk.setFMUstate(saved)
        assert trk.getReal(qd_out) == list(ref.q_d)
        trk.freeFMUstate(saved)
    finally:
        for f in (trk, body):
            f.terminate()
            f.freeInstance()


def test_fmu_rejects_bad_gain(build_one):
    import fmpy
    from fmpy.fmi1 import FMICallException

    path = str(build_one("neighbor_tracking_controller.py"))
    for start, words in [({"G[2]": -0.1}, ["G (diagonal", "-0.1", "positive"]),
                         ({"e[3]": 0.0}, ["saturation thresholds", "positive"]),
                         ({"k": 0.0}, ["k = 0.0", "positive"])]:
        messages = []

        def log(component, instance, status, category, message, messages=messages):
            messages.append(message.decode() if isinstance(message, bytes) else message)

        with pytest.raises(FMICallException):
            fmpy.simulate_fmu(path, stop_time=0.03, output_interval=0.015, start_values=start, logger=log,
                              debug_logging=True)
        assert any(all(w in m for w in words) for m in messages), messages


def _law_by_methods(ctl, q, w, enabled, target, sigma, h, follow):
    """The FMU's outputs (deorbit_tracking.PUBLISHED) by the model's methods, then its step."""
    if follow and enabled:
        ctl.follow(target[:4], target[4:])
    e = ctl.boundary_layer(sigma)
    torque, flags, s, _ = ctl.evaluate(q, w)
    if not enabled:
        torque, flags = [0.0, 0.0, 0.0], [0, 0, 0]
    out = [*torque, *flags, float(all(abs(s[i]) <= e[i] for i in range(3))), ctl.attitude_error(q),
           ctl.pointing_error(q), *ctl.target(q), *s, *e]
    if follow and enabled:
        ctl.follow(target[:4], target[4:])
    ctl.advance(h, q, enabled)
    return out


@pytest.mark.parametrize("compiled", [False, True], ids=["plain", "numba"])
def test_tracking_into_gives_the_methods_bits(compiled):
    """tracking_into, the FMU's step and publish in one kernel (plain Python and compiled), writes
    the methods' values bit for bit over a burn-like sequence: noisy estimates, a sigma that
    changes every step, a guidance target that moves every 33 steps, the law disabled and enabled
    again, both torque forms, the latch and a fixed q_d0."""
    if compiled and not jit.ENABLED:
        pytest.skip("numba is not used here (NEIGHBOR_COSIM_NUMBA=0 or not installed)")
    law = dtr.tracking_into if compiled else jit.function_of(dtr.tracking_into)
    rng = np.random.default_rng(11)
    reads, published = (sum(n for _, n in names) for names in (dtr.READS, dtr.PUBLISHED))
    for kwargs, follow in (({"knowledge_sigmas": 3.0, "impulse_bits": 1.0, "rate_sigma": 1e-4}, True),
                           ({"torque_form": "script_literal", "q_d0": Q0}, False), ({}, True)):
        ref, ctl = dtr.DeorbitTrackingController(J_BOX, **kwargs), dtr.DeorbitTrackingController(J_BOX, **kwargs)
        values = np.zeros(reads + published)
        inputs, outputs = np.arange(reads), np.arange(reads, reads + published)
        target = np.array([*Q0, 0.0, 1.1e-3, 0.0])
        for step in range(600):
            if step % 33 == 0:
                target[:4] = rotations.normalized(target[:4] + rng.normal(0.0, 1e-3, 4))
            q = np.array(Q0) + rng.normal(0.0, 2e-3, 4)
            w = np.array(W0) + rng.normal(0.0, 1e-3, 3)
            enabled = not 200 <= step < 260
            sigma = np.abs(rng.normal(0.0, 1e-3, 3))
            values[:reads] = [*q, *w, float(enabled), *target, *sigma]
            expected = _law_by_methods(ref, tuple(q.tolist()), tuple(w.tolist()), enabled, tuple(target.tolist()),
                                       tuple(sigma.tolist()), H, follow)
            assert law(ctl.constants, ctl.x, values, inputs, outputs, 0.0, False, follow) == 0
            assert values[reads:].tolist() == expected, (kwargs, step)
            assert law(ctl.constants, ctl.x, values, inputs, outputs, H, True, follow) == 0
            assert ctl.get_state() == ref.get_state()
    # what it refuses, it leaves unchanged for the methods to raise the error
    before = ctl.x.copy()
    values[8:12] = 0.0
    assert law(ctl.constants, ctl.x, values, inputs, outputs, H, True, True) == dtr.FOLLOW_REFUSED
    assert ctl.x.tolist() == before.tolist()
