"""Control laws of the ACS of the mode specification (components.acs.control), its signals, paddles and optical
tracker, and their FMUs."""
import math

import pytest

from components.acs import control as ac
from components.acs import (
    magnetorquer,
    momentum_wheel,
    optical_tracker,
    paddles,
    signals,
)
from components.attitude import rigid_body
from paths import REPO

J = rigid_body.box_inertia(12.0, 0.1, 0.2, 0.3)
B0 = (2.0e-5, -1.0e-5, 3.0e-5)
D = math.radians


def closed_loop(mode, omega0, seconds, sun=(0.3, 0.5, 0.8), wheel0=0.0, B=B0, h=1.0, params=None, tim=0.0):
    """Body, coils and wheel in a fixed inertial field and Sun, the law in `mode` in the loop."""
    from components.core import rotations
    c = ac.AcsControl(params)
    body = rigid_body.RigidBody(J, (0, 0, 0, 1), omega0, "rk4", 0.05)
    coils, wheel = magnetorquer.TorqueCoils(), momentum_wheel.MomentumWheel(omega0=wheel0)
    n = math.sqrt(sum(x * x for x in sun))
    sun = [x / n for x in sun]
    t = 0.0
    while t < seconds:
        A = rotations.attitude_matrix(body.q)
        bB = [sum(A[i][j] * B[j] for j in range(3)) for i in range(3)]
        sB = [sum(A[i][j] * sun[j] for j in range(3)) for i in range(3)]
        m, tw = c.command(mode, True, True, body.omega, bB, sB, wheel.rate, tim + t)
        hw = wheel.momentum_B()
        body.step(coils.torque(m, bB)[1], h, wheel.torque_B(tw), hw)
        wheel.step(tw, True, h)
        t += h
    A = rotations.attitude_matrix(body.q)
    sB = [sum(A[i][j] * sun[j] for j in range(3)) for i in range(3)]
    return body, wheel, sB


def test_detumble_y_moment_removes_xz_rate_and_keeps_wheel():
    c = ac.AcsControl()
    w = (D(2), D(2), D(2))
    m, tw = c.command(ac.DETUMBLE, True, True, w, B0, (0, 0, 1), 123.0)
    assert m[0] == 0.0 and m[2] == 0.0 and m[1] != 0.0 and tw == 0.0
    tau = magnetorquer.TorqueCoils([10.0] * 3).torque(m, B0)[1]
    assert sum(a * b for a, b in zip(w, tau)) < 0  # kinetic energy decreases
    body, wheel, _ = closed_loop(ac.DETUMBLE, [D(2)] * 3, 1500.0, wheel0=100.0)
    assert math.hypot(body.omega[0], body.omega[2]) < 0.3 * math.hypot(D(2), D(2))
    assert wheel.rate == 100.0


def test_spinup_increases_y_momentum_toward_target():
    hd = ac.PARAMETER_DEFAULTS["Iy"] * D(5)
    body, _, _ = closed_loop(ac.SPINUP, [0.0, 0.0, 0.0], 3000.0)
    h = body.angular_momentum()
    assert h[1] > 0.5 * hd and math.hypot(h[0], h[2]) < 0.2 * hd
    c = ac.AcsControl()
    m, _ = c.command(ac.SPINUP, True, True, (0, 0, 0), B0, (0, 0, 1), 0.0)
    tau = magnetorquer.TorqueCoils([10.0] * 3).torque(m, B0)[1]
    assert tau[1] > 0


def test_reorient_reduces_sun_y_component():
    w0 = [0.0, D(5), 0.0]
    sun = (0.3, 0.7, 0.6)
    _, _, s = closed_loop(ac.REORIENT, w0, 3000.0, sun=sun, params={"reorient_hold_elevation": 0.0})
    _, _, s0 = closed_loop(ac.REORIENT, w0, 3000.0, sun=sun, params={"reorient_hold_elevation": 0.0,
                                                                   "k_precession": 1e-12})
    assert abs(s[1]) < abs(s0[1]) - 0.01


def test_reorient_holds_elevation_until_duration():
    c = ac.AcsControl({"reorient_duration": 100.0})
    s = (0.0, math.sin(D(12)), math.cos(D(12)))  # inside the hold (15 deg): pushed out, not in
    H = (0.0, ac.PARAMETER_DEFAULTS["Iy"] * D(5), 0.0)
    w = (0.0, D(5), 0.0)
    tau_before = c._momentum_torque(H, s, math.copysign(c.p["reorient_hold_elevation"], s[1]))
    tau_after = c._momentum_torque(H, s, 0.0)
    assert sum(a * b for a, b in zip(s, tau_before)) > 0 > sum(a * b for a, b in zip(s, tau_after))
    assert (c.command(ac.REORIENT, True, True, w, B0, s, 0.0, 50.0)
            != c.command(ac.REORIENT, True, True, w, B0, s, 0.0, 150.0))


def test_deploy_wheel_transfers_momentum_to_wheel_with_coils_off():
    c = ac.AcsControl()
    m, tw = c.command(ac.DEPLOY_WHEEL, False, True, (0, D(5), 0), B0, (0, 0, 1), 0.0)
    assert m == (0.0, 0.0, 0.0) and tw > 0
    body, wheel, _ = closed_loop(ac.DEPLOY_WHEEL, [0.0, D(5), 0.0], 120.0)
    hd = J[1][1] * D(5)
    assert abs(body.omega[1]) < 0.05 * D(5)
    assert wheel.inertia * wheel.rate == pytest.approx(hd, rel=0.05)


def test_acquire_brings_sun_azimuth_to_zero_with_wheel():
    hd = J[1][1] * D(5)
    sun = (math.sin(D(60)), 0.05, math.cos(D(60)))
    body, wheel, s = closed_loop(ac.ACQUIRE, [0.0, 0.0, 0.0], 900.0, sun=sun, wheel0=hd / 2e-5)
    assert abs(math.atan2(s[0], s[2])) < D(5) and abs(wheel.rate) < wheel.max_speed


@pytest.mark.parametrize("mode", range(10))
def test_permissions_and_off_modes(mode):
    c = ac.AcsControl()
    args = ((D(1), D(5), D(1)), B0, (0.5, 0.3, 0.8), 400.0, 10.0)
    m, tw = c.command(mode, False, False, *args)
    assert m == (0.0, 0.0, 0.0) and tw == 0.0
    m, tw = c.command(mode, True, True, *args)
    if mode in (ac.WAIT, ac.DEPLOY_PADDLES, ac.GROUND_COMMAND):
        assert m == (0.0, 0.0, 0.0) and tw == 0.0
    if mode == ac.DEPLOY_WHEEL:
        assert m == (0.0, 0.0, 0.0)


def test_bad_parameters_and_mode():
    with pytest.raises(ValueError, match="k_detumble"):
        ac.AcsControl({"k_detumble": -1.0})
    with pytest.raises(ValueError, match="reorient_hold_elevation"):
        ac.AcsControl({"reorient_hold_elevation": 1.5})
    with pytest.raises(ValueError, match="mode"):
        ac.AcsControl().command(12, True, True, (0, 0, 0), B0, (0, 0, 1), 0.0)


def test_signals_definitions():
    s = signals.AcsSignals({"command_start": 10.0, "command_end": 20.0})
    hd = 0.13 * D(5)
    v = s.values((0.003, 0.5 * hd, -0.004), (0.0, 0.5 * hd, 0.0), (0.0, 0.0, 0.1), (1.0, 1.0, 0.0))
    assert v["xz_momentum_error"] == pytest.approx(0.005)
    assert v["momentum_error"] == pytest.approx(0.005)
    assert v["sin_sun_elevation"] == pytest.approx(math.sqrt(0.5))
    assert v["sin_sun_azimuth"] == pytest.approx(1.0) and v["body_rate"] == pytest.approx(0.1)
    assert not s.ground_command
    s.step(10.0)
    assert s.ground_command
    s.step(10.0)
    assert not s.ground_command


def test_paddles_deploy_after_time_and_latch():
    p = paddles.Paddles(60.0)
    for _ in range(59):
        p.step(True, 1.0)
    assert not p.deployed
    p.step(True, 1.0)
    assert p.deployed
    p.step(False, 1.0)
    assert p.deployed and p.get_state() == {"progress": 60.0, "deployed": True}
    with pytest.raises(ValueError, match="deployment_time"):
        paddles.Paddles(-1.0)


def test_optical_tracker_lock_night_and_loss_after_dawn():
    o = optical_tracker.OpticalTracker(acquisition_time=10.0, loss_time=5.0)
    for _ in range(10):
        assert not o.tracking(False)
        o.step(False, 0.0, True, 1.0)
    assert o.tracking(False) and o.tracking(True)  # at dawn still tracking
    for _ in range(5):
        o.step(True, 0.0, True, 1.0)
    assert not o.tracking(True) and o.tracking(False)
    o.step(False, 1.0, True, 1.0)  # fast rate drops the lock
    assert not o.tracking(False)
    o2 = optical_tracker.OpticalTracker(acquisition_time=0.0)
    assert not o2.conditions(0.0, False)  # needs paddles by default


# ---- FMUs ------------------------------------------------------------------------------
FMUS = ("acs_control", "acs_signals", "paddles", "optical_tracker")


@pytest.fixture(scope="session")
def acs_fmu_dir(tmp_path_factory):
    import build_fmus
    d = tmp_path_factory.mktemp("acs_fmus")
    for n in FMUS:
        build_fmus.build_fmu(REPO / "fmus" / f"neighbor_{n}.py", d)
    return d


@pytest.mark.parametrize("name", ["AcsControl", "AcsSignals", "Paddles", "OpticalTracker"])
def test_fmu_validates_and_simulates(acs_fmu_dir, name):
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu
    path = str(acs_fmu_dir / f"{name}.fmu")
    assert validate_fmu(path) == []
    start = {"AcsControl": {"mode": 4, "wheel_enabled": True, "omega_BN_B[2]": D(5)},
             "AcsSignals": {"H_B[1]": 0.003, "command_start": 1.0, "command_end": 2.0},
             "Paddles": {"deploy": True, "deployment_time": 3.0},
             "OpticalTracker": {"acquisition_time": 2.0, "paddles_deployed": True}}[name]
    r = simulate_fmu(path, stop_time=5.0, output_interval=1.0, start_values=start)
    if name == "AcsControl":
        assert r["wheel_torque_cmd"][-1] == pytest.approx(0.1 * 0.13 * D(5))
    elif name == "AcsSignals":
        assert r["xz_momentum_error"][-1] == pytest.approx(0.003) and any(r["ground_command"])
    elif name == "Paddles":
        assert not r["paddles_deployed"][0] and r["paddles_deployed"][-1]
    else:
        assert not r["tracking"][0] and r["tracking"][-1]


def test_precession_tapers_off_with_the_momentum_error():
    from components.acs import control as ac
    c = ac.AcsControl({"k_momentum": 1e-12})
    hd = c.p["Iy"] * c.p["spin_rate"]
    s = (0.6, 0.5, 0.6)
    full = c._momentum_torque((0.0, hd, 0.0), s, 0.0)
    half = c._momentum_torque((1.5 * c.p["precession_taper"], hd, 0.0), s, 0.0)
    off = c._momentum_torque((2.0 * c.p["precession_taper"], hd, 0.0), s, 0.0)
    g = c.p["k_precession"] * 0.5 * hd
    assert abs(full[0] + g * 0.6) < 1e-12 and abs(full[2] + g * 0.6) < 1e-12
    assert abs(half[2] + 0.5 * g * 0.6) < 1e-10
    assert abs(off[2]) < 1e-10


def test_fine_modes_use_their_own_precession_gain():
    from components.acs import control as ac
    B, s, w = (2e-5, 1e-5, -3e-5), (0.3, 0.2, 0.93), (0.0, 0.0, 0.0)
    wr = 0.13 * ac.PARAMETER_DEFAULTS["spin_rate"] / 2e-5
    a = ac.AcsControl({"k_precession_fine": 1e-3}).command(ac.ORBIT_DAY, True, True, w, B, s, wr)[0]
    b = ac.AcsControl({"k_precession_fine": 2e-3, "k_precession": 7e-3}).command(ac.ORBIT_DAY, True, True, w, B, s,
                                                                                wr)[0]
    assert all(abs(2 * x - y) < 1e-9 for x, y in zip(a, b))
