"""Sun-avoidance slew: guidance geometry and profiles, tracking controller, FMUs, system."""
import math
from pathlib import Path

import numpy as np
import pytest

from components.attitude import reference_tracking as rt
from components.attitude import rigid_body
from components.attitude import sun_avoidance as sa
from components.core import rotations as at
from paths import REPO
from system_ssp.systems.generators import sun_avoidance as gen

J_BOX = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3).tolist()
EPS, MARGIN = gen.EPSILON, gen.MARGIN


def plan(sun, q0=gen.Q0, q_f=gen.Q_F, **kw):
    args = dict(inertia=J_BOX, margin=MARGIN)
    args.update(kw)
    return sa.SunAvoidanceGuidance(gen.BORESIGHT, sun, EPS, q0, q_f, gen.W_MAX, gen.A_MAX, **args)


def q_close(a, b):
    """Largest element difference between a and +-b (same attitude)."""
    return min(max(abs(x - y) for x, y in zip(a, b)), max(abs(x + y) for x, y in zip(a, b)))


def q_angle(a, b):
    dq = at.error_quaternion(at.normalized(a), at.normalized(b))
    return 2.0 * math.acos(min(1.0, abs(dq[3])))


def analytic_tf(phi, w, a):
    return (w / a + phi / w) if phi > w * w / a else 2.0 * math.sqrt(phi / a)


def dense_sun_angles(g, dt=0.02):
    ts = np.arange(g.t_start, g.t_end + dt, dt)
    return np.array([g.reference(t)["sun_angle"] for t in ts])


def random_unit(rng):
    v = rng.normal(size=3)
    return tuple(v / np.linalg.norm(v))


def random_quat(rng):
    v = rng.normal(size=4)
    return tuple(v / np.linalg.norm(v))


# ---- profile ------------------------------------------------------------------------------
def test_trapezoid_profile_analytic_and_consistent():
    w, a, phi = 0.05, 0.01, 1.0
    p = sa.BangCoastBang(phi, w, a)
    assert not p.triangle
    assert p.t1 == pytest.approx(5.0) and p.t2 == pytest.approx(5.0 + (1.0 - 0.25) / 0.05)
    assert p.tf == pytest.approx(p.t2 + 5.0) and p.tf == pytest.approx(analytic_tf(phi, w, a))
    assert p.evaluate(p.tf) == (phi, 0.0, 0.0) and p.evaluate(-1.0) == (0.0, 0.0, 0.0)
    assert max(p.evaluate(t)[1] for t in np.linspace(0, p.tf, 1001)) == pytest.approx(w)
    # The angle is the integral of the rate, the rate the integral of the acceleration.
    ts = np.linspace(0.0, p.tf, 20001)
    vals = np.array([p.evaluate(t) for t in ts])
    rate_int = np.concatenate([[0.0], np.cumsum(0.5 * (vals[1:, 1] + vals[:-1, 1]) * np.diff(ts))])
    acc_int = np.concatenate([[0.0], np.cumsum(0.5 * (vals[1:, 2] + vals[:-1, 2]) * np.diff(ts))])
    assert np.max(np.abs(rate_int - vals[:, 0])) < 1e-6
    # trapezoid rule across the 3 acceleration jumps: at most a dt / 2 each
    assert np.max(np.abs(acc_int - vals[:, 1])) <= 3 * a * (ts[1] - ts[0]) / 2 + 1e-12
    for tb in (p.t1, p.t2):  # continuity of angle and rate at the switching times
        lo, hi = p.evaluate(tb - 1e-9), p.evaluate(tb)
        assert abs(lo[0] - hi[0]) < 1e-9 and abs(lo[1] - hi[1]) < 1e-9


def test_triangle_profile_for_short_angle():
    w, a = 0.05, 0.01  # phi_tt = 0.25 rad
    p = sa.BangCoastBang(0.1, w, a)
    assert p.triangle and p.t1 == p.t2 == pytest.approx(math.sqrt(0.1 / 0.01))
    assert p.tf == pytest.approx(2 * math.sqrt(10.0))
    assert p.evaluate(p.t1)[0] == pytest.approx(0.05)
    assert p.w_peak == pytest.approx(math.sqrt(0.1 * 0.01)) and p.w_peak < w
    assert p.evaluate(p.t1)[2] == -a and p.evaluate(p.t1 - 1e-9)[2] == a  # no coast phase
    # a whole short slew through the guidance gives one triangle segment
    q_f = at.from_axis_angle((0.0, 1.0, 0.0), 0.1)
    g = sa.SunAvoidanceGuidance((0, 0, 1), (1, 0, 0), EPS, gen.Q0, q_f, w, a, inertia=J_BOX)
    assert len(g.segments) == 1 and g.segments[0].profile.triangle
    assert g.duration == pytest.approx(2 * math.sqrt(0.1 / a), rel=1e-12)


# ---- swept-arc test -----------------------------------------------------------------------
def _seed_times(phi, w, a, w0, wf):
    """Seed 000, step 2b, as written (t0 = 0): the switching times with start and end rates."""
    t1 = (w - w0) / a
    t2 = t1 + (phi - w0 * t1 - 0.5 * a * t1 ** 2 - w * (w - wf) / a + (w - wf) ** 2 / (2 * a)) / w
    tf = t1 + (phi - w0 * t1 - 0.5 * a * t1 ** 2 + (w - wf) ** 2 / (2 * a)) / w
    return t1, t2, tf


@pytest.mark.parametrize("phi,w0,wf", [(1.0, 0.02, 0.03), (1.0, 0.05, 0.0), (0.6, 0.0, 0.04), (2.0, 0.01, 0.01)])
def test_profile_from_and_to_a_moving_state_follows_the_seed(phi, w0, wf):
    w, a = 0.05, 0.01
    p = sa.BangCoastBang(phi, w, a, w0, wf)
    assert not p.triangle
    assert (p.t1, p.t2, p.tf) == pytest.approx(_seed_times(phi, w, a, w0, wf), rel=1e-12, abs=1e-12)
    assert p.evaluate(0.0)[1] == w0 and p.evaluate(p.tf)[:2] == (phi, wf)
    assert p.evaluate(p.tf + 10.0)[:2] == pytest.approx((phi + 10.0 * wf, wf))  # goes on at the end rate
    ts = np.linspace(0.0, p.tf, 20001)
    vals = np.array([p.evaluate(t) for t in ts])
    assert np.all(np.diff(vals[:, 0]) >= 0.0) and vals[:, 1].max() <= w + 1e-15  # monotone, rate-limited
    rate_int = np.concatenate([[0.0], np.cumsum(0.5 * (vals[1:, 1] + vals[:-1, 1]) * np.diff(ts))])
    assert np.max(np.abs(rate_int - vals[:, 0])) < 1e-6  # the angle is the rate's integral
    for tb in (p.t1, p.t2, p.tf):
        lo, hi = p.evaluate(tb - 1e-9), p.evaluate(tb)
        assert abs(lo[0] - hi[0]) < 1e-9 and abs(lo[1] - hi[1]) < 1e-9
    # a moving start or end is quicker than rest to rest
    assert p.tf < sa.BangCoastBang(phi, w, a).tf


def test_short_profile_between_rates_and_refusals():
    w, a = 0.05, 0.01
    p = sa.BangCoastBang(0.1, w, a, 0.01, 0.02)
    assert p.triangle and p.w_peak < w
    assert p.w_peak == pytest.approx(math.sqrt(a * 0.1 + (0.01 ** 2 + 0.02 ** 2) / 2), rel=1e-12)
    assert p.evaluate(p.tf)[:2] == (pytest.approx(0.1), 0.02) and p.tf == pytest.approx(
        (2 * p.w_peak - 0.01 - 0.02) / a)
    # too short to slow from 0.05 to rest (0.125 rad needed), rates outside [0, w_max]
    with pytest.raises(ValueError, match="too short to go from 0.05 to 0.0 rad/s"):
        sa.BangCoastBang(0.1, w, a, 0.05, 0.0)
    for w0, wf in ((-0.01, 0.0), (0.0, 0.06), (math.nan, 0.0)):
        with pytest.raises(ValueError, match="must lie in \\[0, w_max"):
            sa.BangCoastBang(1.0, w, a, w0, wf)
    with pytest.raises(ValueError, match="no slew to start at phi_dot_0"):
        plan(gen.sun_far(), q_f=gen.Q0, phi_dot_0=0.01)


@pytest.mark.parametrize("sun", ["near", "far"])
def test_guidance_from_and_to_a_moving_state(sun):
    """The first segment starts at phi_dot_0 along its axis, the last ends at phi_dot_f; the
    segments between meet at rest; the keep-out cone is never entered."""
    S = gen.sun_near() if sun == "near" else gen.sun_far()
    rest, g = plan(S), plan(S, phi_dot_0=0.02, phi_dot_f=0.015)
    assert len(g.segments) == len(rest.segments) and g.duration < rest.duration
    first, last = g.segments[0], g.segments[-1]
    assert g.reference(g.t_start)["omega"] == pytest.approx([0.02 * x for x in first.axis_B], abs=1e-15)
    end = g.reference(g.t_end)
    assert end["omega"] == pytest.approx([0.015 * x for x in last.axis_B], abs=1e-15) and end["done"]
    assert q_close(end["q"], gen.Q_F) < 1e-12
    for a, b in zip(g.segments, g.segments[1:]):  # at rest where the axis changes
        assert a.profile.wf == 0.0 and b.profile.w0 == 0.0
    assert dense_sun_angles(g).min() >= EPS and g.min_angle >= EPS


def test_min_sun_angle_matches_brute_force_and_seed_alpha():
    rng = np.random.default_rng(1)
    for _ in range(200):
        P, e, S = (np.array(random_unit(rng)) for _ in range(3))
        phi = rng.uniform(0, 2 * math.pi)
        ang, th = sa.min_sun_angle(tuple(P), tuple(e), phi, tuple(S))
        t = np.linspace(0, phi, 20001)[:, None]  # Rodrigues, vectorized
        path = P * np.cos(t) + np.cross(e, P) * np.sin(t) + np.outer(1 - np.cos(t), e * (e @ P))
        brute = np.arccos(np.clip(path @ S, -1, 1)).min()
        assert ang <= brute + 1e-12 and brute - ang < 1e-5 and 0 <= th <= phi
    # Great circle (e perpendicular to P) with the Sun's projection inside the arc: |alpha|.
    P, e = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    S = sa._unit((math.cos(1.0), math.sin(1.0), 0.2), "S")
    alpha = math.pi / 2 - math.acos(at.dot(S, e))
    assert sa.min_sun_angle(P, e, 2.0, S)[0] == pytest.approx(abs(alpha), abs=1e-12)


# ---- plans --------------------------------------------------------------------------------
def test_far_sun_single_eigenaxis():
    g = plan(gen.sun_far())
    axis, phi = sa.eigenaxis(gen.Q0, gen.Q_F)
    assert not g.intrudes and len(g.segments) == 1 and g.path_kind == "direct"
    assert g.segments[0].angle == pytest.approx(phi, abs=1e-12)
    assert np.allclose(g.segments[0].axis_B, axis, atol=1e-12)
    assert g.duration == pytest.approx(analytic_tf(phi, gen.W_MAX, gen.A_MAX), rel=1e-12)
    assert q_close(g.q_end, gen.Q_F) < 1e-12
    assert dense_sun_angles(g).min() >= EPS


def test_near_sun_three_segment_geometry():
    g = plan(gen.sun_near())
    S, eps_d = g.S, EPS + MARGIN
    assert g.intrudes and g.direct_min_angle == pytest.approx(math.radians(10.0), abs=1e-9)
    assert len(g.segments) == 3 and g.path_kind == "cone-eigenaxis"
    assert g.duration == min(d for d, _ in g.candidates.values())
    s1, s2, s3 = g.segments
    # segment angles: onto the eps_d cone and off it
    assert s1.angle == pytest.approx(g.theta_i - eps_d, abs=1e-12)
    assert s3.angle == pytest.approx(g.theta_f - eps_d, abs=1e-12)
    P1, P2 = sa.boresight_N(s1.q_end, g.P), sa.boresight_N(s2.q_end, g.P)
    assert sa.angle_between(P1, S) == pytest.approx(eps_d, abs=1e-12)
    assert sa.angle_between(P2, S) == pytest.approx(eps_d, abs=1e-12)
    assert abs(at.dot(P1, at.cross(g.P_i, S))) < 1e-12  # segment 1 in the plane of P_i and S
    assert abs(at.dot(P2, at.cross(g.P_f, S))) < 1e-12  # segment 3 in the plane of S and P_f
    # continuity: attitude continuous at the boundaries, rates zero there, final attitude reached
    for a, b in ((s1, s2), (s2, s3)):
        assert a.t_end == b.t_begin
        assert q_close(a.q_end, b.q_start) < 1e-15
        before, after = g.reference(a.t_end - 1e-9), g.reference(a.t_end)
        assert q_close(before["q"], after["q"]) < 1e-9
        assert max(map(abs, after["omega"])) == 0.0 and max(map(abs, before["omega"])) < 1e-10
    assert q_close(g.q_end, gen.Q_F) < 1e-12 and g.reference(g.t_end)["done"]
    assert not g.reference(g.t_end - 1e-6)["done"]
    # duration = sum of the analytic segment durations
    assert g.duration == pytest.approx(sum(analytic_tf(s.angle, gen.W_MAX, gen.A_MAX) for s in g.segments), rel=1e-12)
    angles = dense_sun_angles(g, 0.01)
    assert angles.min() >= EPS and angles.min() == pytest.approx(eps_d, abs=1e-6)
    # segment indices in order
    idx = [g.reference(t)["segment"] for t in np.linspace(0, g.t_end, 500)]
    assert idx == sorted(idx) and set(idx) == {1, 2, 3}


def test_random_plans_avoid_sun_and_reach_target():
    rng = np.random.default_rng(7)
    n3 = 0
    for _ in range(60):
        P, q0, q_f = random_unit(rng), random_quat(rng), random_quat(rng)
        # the Sun near the direct path's midpoint boresight (often intruding), or anywhere
        axis, phi = sa.eigenaxis(q0, q_f)
        mid = sa.boresight_N(at.circle_cross(at.from_axis_angle(axis, phi / 2), q0), P)
        S = sa.rotate(mid, random_unit(rng), rng.uniform(0, 0.6)) if rng.uniform() < 0.7 else random_unit(rng)
        try:
            g = sa.SunAvoidanceGuidance(P, S, math.radians(25), q0, q_f, 0.1, 0.05, inertia=J_BOX, margin=0.05)
        except ValueError as exc:  # an end boresight inside the cone: the only refusal
            assert "keep-out cone" in str(exc)
            continue
        n3 += len(g.segments) == 3
        if g.intrudes:  # the cone-eigenaxis candidate is safe by construction, always
            assert g.candidates["cone-eigenaxis"][1] >= min(math.radians(25) + 0.05, g.theta_i, g.theta_f) - 1e-9
        assert q_close(g.q_end, q_f) < 1e-12
        assert dense_sun_angles(g, 0.05).min() >= math.radians(25)
    assert n3 >= 15


def test_reference_matches_propagated_kinematics():
    """q from q_dot = 1/2 Xi(q) omega_ref (RK4, 10 ms) equals the analytic q_ref."""
    g = plan(gen.sun_near())
    q, h, t = g.q0, 0.01, 0.0
    worst = 0.0
    f = lambda tt, qq: at.quaternion_rate(qq, g.reference(tt)["omega"])  # noqa: E731
    while t < g.t_end + 1.0:
        k1 = f(t, q)
        k2 = f(t + h / 2, [q[i] + h / 2 * k1[i] for i in range(4)])
        k3 = f(t + h / 2, [q[i] + h / 2 * k2[i] for i in range(4)])
        k4 = f(t + h, [q[i] + h * k3[i] for i in range(4)])
        q = [q[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(4)]
        t += h
        worst = max(worst, q_angle(q, g.reference(t)["q"]))
    assert worst < 1e-6
    assert q_angle(q, gen.Q_F) < 1e-6


def test_feed_forward_is_euler_equation():
    g = plan(gen.sun_near())
    J = np.array(J_BOX)
    for t in (1.0, 3.0, 20.0, 60.0, 100.0, 130.0):
        r = g.reference(t)
        w, wd = np.array(r["omega"]), np.array(r["omega_dot"])
        assert np.allclose(r["torque_ff"], J @ wd + np.cross(w, J @ w), atol=1e-15)
    assert np.linalg.norm(np.cross(g.reference(30.0)["omega"], J @ g.reference(30.0)["omega"])) > 1e-6


def test_state_and_bad_parameters():
    g = plan(gen.sun_near())
    g.step(42.0)
    st = g.get_state()
    g.step(100.0)
    g.set_state(st)
    assert g.time == 42.0 and g.reference() == g.reference(42.0)
    S = gen.sun_near()
    bad = [dict(epsilon=0.0), dict(epsilon=math.pi / 2), dict(epsilon=-0.1), dict(w_max=0.0), dict(w_max=-1.0),
           dict(a_max=0.0), dict(q0=(0, 0, 0, 0)), dict(q_f=(0, 0, 0, 0)), dict(boresight_B=(0, 0, 0)),
           dict(sun_N=(0, 0, 0)), dict(margin=-0.1), dict(w_max=float("nan"))]
    for kw in bad:
        args = dict(boresight_B=gen.BORESIGHT, sun_N=S, epsilon=EPS, q0=gen.Q0, q_f=gen.Q_F, w_max=0.05, a_max=0.01)
        args.update(kw)
        name = next(iter(kw)).replace("boresight_B", "boresight").replace("sun_N", "sun")
        with pytest.raises(ValueError, match=name.split("_")[0]):
            sa.SunAvoidanceGuidance(**args)
    with pytest.raises(ValueError, match="keep-out cone"):  # initial boresight inside the cone
        sa.SunAvoidanceGuidance((0, 0, 1), (0, 0.1, 1), EPS, gen.Q0, gen.Q_F, 0.05, 0.01)


# ---- tracking controller ------------------------------------------------------------------
def test_tracker_command_modes_and_done():
    c = rt.ReferenceTrackingController(Kp=(0.1, 0.2, 0.3), Kd=(0.01, 0.02, 0.03), max_torque=(1e-3,) * 3)
    q_ref = at.from_axis_angle((0, 0, 1), 0.3)
    q = at.circle_cross(at.from_axis_angle((1, 0, 0), 0.01), q_ref)  # 0.01 rad about x off the reference
    raw = c.raw_torque(q, (0.0, 0.0, 0.001), q_ref, (0.0, 0.0, 0.002), (1e-4, -2e-4, 3e-5))
    dq = at.error_quaternion(q, q_ref)
    assert dq[0] == pytest.approx(math.sin(0.005))
    assert raw == pytest.approx([1e-4 - 0.1 * math.sin(0.005), -2e-4, 3e-5 + 0.03 * 0.001], abs=1e-15)
    torque, flags = c.command(q, (0.0, 0.0, 0.001), q_ref, (0.0, 0.0, 0.002), (1e-4, -2e-4, 3e-5))
    assert torque == pytest.approx([-1e-3 * 0 + max(-1e-3, raw[0]), -2e-4, raw[2]]) and flags == [-1, -1, 1]
    # sign(dq4): -q is the same attitude, the same torque
    assert c.raw_torque([-x for x in q], (0, 0, 0), q_ref, (0, 0, 0), (0, 0, 0)) == pytest.approx(
        c.raw_torque(q, (0, 0, 0), q_ref, (0, 0, 0), (0, 0, 0)))
    cq = rt.ReferenceTrackingController(Kp=(0.1, 0.2, 0.3), Kd=(0.01, 0.02, 0.03), max_torque=(1e-4,) * 3,
                                        quantize=True)
    t2, f2 = cq.command(q, (0.0, 0.0, 0.001), q_ref, (0.0, 0.0, 0.002), (1e-4, -2e-4, 3e-5))
    assert t2 == [-1e-4, -1e-4, 0.0] and f2 == [-1, -1, 0]
    assert not c.done(q_ref, (0, 0, 0), q_ref, (0, 0, 0), False)
    assert c.done(q_ref, (0, 0, 0), q_ref, (0, 0, 0), True)
    assert not c.done(q, (0, 0, 0), q_ref, (0, 0, 0), True)  # 0.01 rad > 0.1 deg
    assert not c.done(q_ref, (0, 0.001, 0), q_ref, (0, 0, 0), True)
    for kw in (dict(Kp=(-1, 0, 0)), dict(max_torque=(0, 1, 1)), dict(angle_tol=0.0), dict(rate_tol=-1.0)):
        with pytest.raises(ValueError, match=next(iter(kw))):
            rt.ReferenceTrackingController(**kw)


# ---- FMUs and system ----------------------------------------------------------------------
@pytest.fixture(scope="session")
def sas_build(tmp_path_factory):
    import build_fmus

    d = tmp_path_factory.mktemp("sas_fmus")
    fmus = {Path(s).stem: build_fmus.build_fmu(REPO / "fmus" / f"{s}.py", d)
            for s in ("neighbor_sun_avoidance_guidance", "neighbor_reference_tracking_controller",
                      "neighbor_rigid_body")}
    ssp = build_fmus.pack_ssp(REPO / "system_ssp" / "systems" / "sun_avoidance_slew.ssd", d, d)
    return fmus, ssp


def test_fmus_validate_and_simulate_alone(sas_build):
    import fmpy
    from fmpy.validation import validate_fmu

    fmus, _ = sas_build
    for path in fmus.values():
        assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(fmus["neighbor_sun_avoidance_guidance"]))
    assert md.outputs and all(not u.dependencies for u in md.outputs)  # time-only outputs
    params = {f"sun_N[{i}]": v for i, v in enumerate(gen.sun_near(), 1)}
    params.update({f"q_f[{i}]": v for i, v in enumerate(gen.Q_F, 1)})
    res = fmpy.simulate_fmu(str(fmus["neighbor_sun_avoidance_guidance"]), stop_time=140.0, output_interval=0.1,
                            start_values=params, output=["done", "duration", "segment_count", "sun_angle",
                                                         "q_ref_BN[1]", "q_ref_BN[2]", "q_ref_BN[3]", "q_ref_BN[4]"])
    g = plan(gen.sun_near())
    assert res["duration"][-1] == pytest.approx(g.duration) and res["segment_count"][-1] == 3
    assert res["done"][-1] and not res["done"][0] and res["sun_angle"].min() >= EPS
    assert q_close([res[f"q_ref_BN[{i}]"][-1] for i in range(1, 5)], gen.Q_F) < 1e-12
    res = fmpy.simulate_fmu(str(fmus["neighbor_reference_tracking_controller"]), stop_time=1.0, output_interval=0.5,
                            start_values={"q_BN[1]": 0.1, "q_BN[4]": 1.0, "guidance_done": True})
    assert res["torque_cmd_B[1]"][-1] < 0 and not res["done"][-1]


def test_guidance_fmu_state_restore(sas_build):
    import shutil

    import fmpy
    from fmpy.fmi2 import FMU2Slave

    fmus, _ = sas_build
    path = str(fmus["neighbor_sun_avoidance_guidance"])
    md = fmpy.read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unz = fmpy.extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unz, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="g")
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vr[f"sun_N[{i}]"] for i in (1, 2, 3)], gen.sun_near())
        fmu.setReal([vr[f"q_f[{i}]"] for i in (1, 2, 3, 4)], list(gen.Q_F))
        fmu.exitInitializationMode()
        refs = [vr[f"q_ref_BN[{i}]"] for i in (1, 2, 3, 4)] + [vr["sun_angle"]]
        t = 0.0
        for _ in range(100):
            fmu.doStep(t, 0.5)
            t += 0.5
        state = fmu.getFMUstate()
        saved = fmu.getReal(refs)
        for _ in range(50):
            fmu.doStep(t, 0.5)
            t += 0.5
        assert fmu.getReal(refs) != saved
        fmu.setFMUstate(state)
        assert fmu.getReal(refs) == saved
        ref = plan(gen.sun_near()).reference(50.0)
        assert q_close(saved[:4], ref["q"]) < 1e-12
        fmu.freeFMUstate(state)
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(unz, ignore_errors=True)


@pytest.mark.parametrize("scenario,n_seg", [("near_sun", 3), ("far_sun", 1)])
def test_system_flies_around_the_sun(sas_build, scenario, n_seg):
    import system_ssp

    _, ssp = sas_build
    q_names = [f"dynamics.q_BN[{i}]" for i in (1, 2, 3, 4)]
    w_names = [f"dynamics.omega_BN_B[{i}]" for i in (1, 2, 3)]
    r = system_ssp.simulate(ssp, parameter_sets=[f"parameters/sun_avoidance_slew_{scenario}.ssv"],
                            outputs=q_names + w_names + ["guidance.sun_angle", "guidance.segment_count",
                                                         "guidance.duration", "tracker.attitude_error",
                                                         "guidance.segment"])
    sun = gen.sun_near() if scenario == "near_sun" else gen.sun_far()
    g = plan(sun)
    assert "tracker.done" in r.stop_reason
    assert r.final["guidance.segment_count"] == n_seg and r.final["guidance.duration"] == pytest.approx(g.duration)
    # stops within 1 s after the planned end
    assert g.duration <= r.stop_time <= g.duration + 1.0
    d = r.data
    assert d["guidance.sun_angle"].min() >= EPS  # every recorded reference step
    flown = np.array([sa.angle_between(sa.boresight_N([d[n][k] for n in q_names], gen.BORESIGHT), g.S)
                      for k in range(len(d))])
    assert flown.min() >= EPS  # every step of the flown attitude
    if scenario == "near_sun":
        assert flown.min() > EPS + 0.9 * MARGIN  # tracking error small against the margin
        assert set(d["guidance.segment"]) == {1, 2, 3}
    assert d["tracker.attitude_error"].max() < math.radians(0.05)
    q_end = [r.final[n] for n in q_names]
    assert q_angle(q_end, gen.Q_F) <= math.radians(0.1)
    assert max(abs(r.final[n]) for n in w_names) <= math.radians(0.01)


def test_system_slews_from_and_to_a_moving_state(sas_build):
    """The spacecraft still turning along the first segment's axis at the start (the detumble's
    residual rate), handed over at phi_dot_f: flown around the Sun, never inside the cone."""
    import system_ssp

    _, ssp = sas_build
    q_names = [f"dynamics.q_BN[{i}]" for i in (1, 2, 3, 4)]
    w_names = [f"dynamics.omega_BN_B[{i}]" for i in (1, 2, 3)]
    g = plan(gen.sun_near(), phi_dot_0=0.02, phi_dot_f=0.01)
    start = {f"dynamics.omega0[{i}]": 0.02 * x for i, x in enumerate(g.segments[0].axis_B, 1)}
    r = system_ssp.simulate(ssp, parameter_sets=["parameters/sun_avoidance_slew_near_sun.ssv"],
                            parameters={**start, "guidance.phi_dot_0": 0.02, "guidance.phi_dot_f": 0.01},
                            stop_time=round(g.t_end / 0.1) * 0.1, outputs=q_names + w_names + [
                                "guidance.sun_angle", "guidance.duration", "tracker.attitude_error"])
    assert r.final["guidance.duration"] == pytest.approx(g.duration) and r.stop_time == pytest.approx(g.t_end, abs=0.1)
    d = r.data
    flown = np.array([sa.angle_between(sa.boresight_N([d[n][k] for n in q_names], gen.BORESIGHT), g.S)
                      for k in range(len(d))])
    assert d["guidance.sun_angle"].min() >= EPS and flown.min() >= EPS
    assert d["tracker.attitude_error"].max() < math.radians(0.05)
    # handed over turning about the last axis, as the reference at that instant (the run stops on
    # its 0.1 s grid, within 0.05 s of the planned end: 0.01 rad/s give or take 5e-4)
    w_end = np.array([r.final[n] for n in w_names])
    assert w_end == pytest.approx(g.reference(r.stop_time)["omega"], abs=3e-5)
    assert np.linalg.norm(w_end) == pytest.approx(0.01, abs=6e-4)
    assert np.dot(w_end, g.segments[-1].axis_B) == pytest.approx(np.linalg.norm(w_end), rel=1e-3)


def test_start_attitude_must_match_the_dynamics():
    """The guidance plans from q0; a spacecraft that starts elsewhere is refused, naming both."""
    q0 = at.normalized((0.1, 0.2, 0.3, 0.9), "q")
    sa.check_start(q0, q0, 1e-6)
    sa.check_start(q0, tuple(-x for x in q0), 1e-6)  # the same attitude
    sa.check_start(q0, (0.0, 0.0, 0.0, 0.0), 1e-6)  # not connected
    with pytest.raises(ValueError, match=r"q0 .* is 11.46 deg away from the attitude at the start"):
        sa.check_start(q0, at.circle_cross(at.from_axis_angle((0.0, 0.0, 1.0), 0.2), q0), 1e-6)
    with pytest.raises(ValueError, match="must be finite"):
        sa.check_start(q0, (math.nan, 0.0, 0.0, 1.0), 1e-6)
