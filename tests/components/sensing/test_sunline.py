"""The sunline module description: MRP conversions (components.core.mrp), the sunline-ephemeris model, its FMU
`SunlineEphemeris` through FMPy, and the `sunline` system through the master."""
import math

import fmpy
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
import numpy as np
import pytest

from components.core import mrp, rotations
from components.sensing import sunline
from paths import REPO, SYSTEMS
from system_ssp.systems.generators import sunline as g

AXES = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0)]
TAN_PI_8 = math.sqrt(2.0) - 1.0  # |sigma| of a 90 deg rotation: tan(90 deg / 4)


def random_quaternions(n, seed=4):
    rng = np.random.default_rng(seed)
    qs = rng.normal(size=(n, 4))
    qs /= np.linalg.norm(qs, axis=1)[:, None]
    return [tuple(float(x) for x in q) for q in qs]


# ---- MRP conversions --------------------------------------------------------------------
def test_mrp_dcm_equals_attitude_matrix_for_q_and_minus_q():
    for q in random_quaternions(500):
        A = np.array(rotations.attitude_matrix(q))
        for qq in (q, tuple(-x for x in q)):
            sigma = mrp.from_quaternion(qq)
            assert np.abs(np.array(mrp.to_dcm(sigma)) - A).max() < 1e-13
            assert np.abs(np.array(mrp.to_dcm(mrp.from_quaternion(qq, short=True))) - A).max() < 1e-13
        C = np.array(mrp.to_dcm(mrp.from_quaternion(q)))
        assert np.abs(C @ C.T - np.eye(3)).max() < 1e-14 and np.linalg.det(C) == pytest.approx(1.0, abs=1e-14)


def test_mrp_known_values():
    # sigma = e tan(phi/4) (Schaub and Junkins); 90 deg about z maps N x to -B y
    sigma = mrp.from_quaternion(rotations.from_axis_angle((0.0, 0.0, 1.0), math.pi / 2))
    assert sigma == pytest.approx((0.0, 0.0, TAN_PI_8), abs=1e-15)
    assert np.array(mrp.to_dcm(sigma)) == pytest.approx(np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1]]), abs=1e-15)
    sigma = mrp.from_quaternion(rotations.from_axis_angle((1.0, 1.0, 1.0), 2.0))
    assert sigma == pytest.approx([math.tan(0.5) / math.sqrt(3.0)] * 3, rel=1e-14)
    assert mrp.to_dcm((0.0, 0.0, 0.0)) == ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    # 180 deg: |sigma| = 1, shadow set = -sigma
    sigma = mrp.from_quaternion(rotations.from_axis_angle((0.0, 1.0, 0.0), math.pi))
    assert sigma == pytest.approx((0.0, 1.0, 0.0), abs=1e-15)
    assert mrp.shadow(sigma) == pytest.approx((0.0, -1.0, 0.0), abs=1e-15)


def test_mrp_quaternion_round_trip_shadow_and_short_sets():
    for q in random_quaternions(300, seed=7):
        sigma = mrp.from_quaternion(q)
        back = mrp.to_quaternion(sigma)
        assert np.array(back) == pytest.approx(np.array(q), abs=1e-13)  # sigma(q) returns q itself
        s = mrp.shadow(sigma)
        assert np.array(mrp.to_quaternion(s)) == pytest.approx(-np.array(q), abs=1e-13)  # the other sign
        assert np.array(mrp.shadow(s)) == pytest.approx(np.array(sigma), rel=1e-13, abs=1e-15)
        assert np.abs(np.array(mrp.to_dcm(s)) - np.array(mrp.to_dcm(sigma))).max() < 1e-13
        short = mrp.short(sigma)
        assert rotations.norm(short) <= 1.0
        assert mrp.short(s) == pytest.approx(short, abs=1e-14)
        assert short == pytest.approx(mrp.from_quaternion(q, short=True), abs=1e-14)
        assert (short == sigma) == (q[3] >= 0.0)  # sigma = q_v/(1+q4) is short exactly when q4 >= 0


def test_dcm_to_mrp_round_trip():
    for q in random_quaternions(300, seed=11) + [rotations.from_axis_angle(a, math.pi) for a in AXES[:3]]:
        A = rotations.attitude_matrix(q)
        sigma = mrp.from_dcm(A)
        assert rotations.norm(sigma) <= 1.0 + 1e-15
        assert np.abs(np.array(mrp.to_dcm(sigma)) - np.array(A)).max() < 1e-13
        qq = mrp.dcm_to_quaternion(A)
        assert qq[3] >= 0.0 and np.abs(np.abs(np.dot(qq, q)) - 1.0) < 1e-13


@pytest.mark.parametrize("call, words", [
    (lambda: mrp.from_quaternion((0.0, 0.0, 0.0, -1.0)), ["q4 = -1", "short=True"]),
    (lambda: mrp.from_quaternion((0.0, 0.0, 0.0, 0.0)), ["zero"]),
    (lambda: mrp.from_quaternion((0.0, math.nan, 0.0, 1.0)), ["q_BN", "finite"]),
    (lambda: mrp.shadow((0.0, 0.0, 0.0)), ["no shadow set"]),
    (lambda: mrp.to_dcm((1.0, math.inf, 0.0)), ["sigma_BN", "finite"]),
    (lambda: mrp.from_dcm(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.1))), ["orthonormal"]),
    (lambda: mrp.from_dcm(((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, -1.0))), ["determinant"]),
])
def test_mrp_errors(call, words):
    with pytest.raises(ValueError) as exc:
        call()
    assert all(w in str(exc.value) for w in words), str(exc.value)
    assert mrp.from_quaternion((0.0, 0.0, 0.0, -1.0), short=True) == (0.0, 0.0, 0.0)


# ---- sunline model ----------------------------------------------------------------------
def _rotated_z90(d):
    # B = N rotated +90 deg about z: b_x = n_y, b_y = -n_x, b_z = n_z
    return (d[1], -d[0], d[2])


def _rotated_x90(d):
    # B = N rotated +90 deg about x: b_x = n_x, b_y = n_z, b_z = -n_y
    return (d[0], d[2], -d[1])


@pytest.mark.parametrize("r_sc", AXES)
@pytest.mark.parametrize("rotation", ["none", "z90", "x90"])
def test_seed_cases_sun_at_origin(r_sc, rotation):
    """The module description's unit test: Sun at [0,0,0], spacecraft on each unit axis, zero attitude and 90 deg
    rotations about z (the module description's case) and x; expected vectors to 1e-12."""
    d_N = tuple(-x for x in r_sc)
    axis, expected = {"none": ((0.0, 0.0, 1.0), d_N), "z90": ((0.0, 0.0, 1.0), _rotated_z90(d_N)),
                      "x90": ((1.0, 0.0, 0.0), _rotated_x90(d_N))}[rotation]
    angle = 0.0 if rotation == "none" else math.pi / 2
    sigma = tuple(a * math.tan(angle / 4) for a in axis)
    q = rotations.from_axis_angle(axis, angle)
    got = sunline.sun_heading_B((0.0, 0.0, 0.0), r_sc, sigma)
    assert max(abs(g - e) for g, e in zip(got, expected)) < 1e-12
    got_q = sunline.sun_heading_B_quaternion((0.0, 0.0, 0.0), r_sc, q)
    assert max(abs(g - e) for g, e in zip(got_q, expected)) < 1e-12
    model = sunline.SunlineEphemeris("mrp")
    h, dist = model.heading((0.0, 0.0, 0.0), r_sc, sigma)
    assert h == got and dist == 1.0


def test_heading_is_the_unit_vector_to_the_sun():
    r_sun, r_sc = (1.2e11, -8.0e10, 3.0e10), (4.2e6, 5.1e6, 1.9e6)
    d, dist = sunline.sun_vector_N(r_sun, r_sc)
    diff = np.array(r_sun) - np.array(r_sc)
    assert dist == pytest.approx(np.linalg.norm(diff), rel=1e-15)
    assert np.array(d) == pytest.approx(diff / np.linalg.norm(diff), abs=1e-15)
    # toward the Sun: moving the spacecraft toward the Sun keeps the heading
    d2, dist2 = sunline.sun_vector_N(r_sun, np.array(r_sc) + 1e9 * np.array(d))
    assert np.array(d2) == pytest.approx(np.array(d), abs=1e-12) and dist2 == pytest.approx(dist - 1e9, rel=1e-12)


def test_shadow_set_and_quaternion_input_give_the_same_heading():
    rng = np.random.default_rng(404)
    negative_q4 = 0
    for q in random_quaternions(300, seed=404):
        r_sun = tuple(rng.normal(size=3) * 1.5e11)
        r_sc = tuple(rng.normal(size=3) * 7e6)
        sigma = mrp.from_quaternion(q)
        h = sunline.sun_heading_B(r_sun, r_sc, sigma)
        assert abs(rotations.norm(h) - 1.0) < 1e-14
        h_shadow = sunline.sun_heading_B(r_sun, r_sc, mrp.shadow(sigma))
        assert max(abs(a - b) for a, b in zip(h, h_shadow)) < 1e-12
        for qq in (q, tuple(-x for x in q), tuple(3.7 * x for x in q)):  # either sign, any norm
            h_q = sunline.sun_heading_B_quaternion(r_sun, r_sc, qq)
            assert max(abs(a - b) for a, b in zip(h, h_q)) < 1e-12
        model_q, model_s = sunline.SunlineEphemeris("quaternion"), sunline.SunlineEphemeris("mrp")
        assert max(abs(a - b) for a, b in zip(model_q.heading(r_sun, r_sc, q_BN=q)[0],
                                              model_s.heading(r_sun, r_sc, sigma_BN=sigma)[0])) < 1e-12
        negative_q4 += q[3] < 0
    assert negative_q4 > 100


@pytest.mark.parametrize("r_sun, r_sc", [((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
                                         ((1.0, 2.0, 3.0), (1.0, 2.0, 3.0)),
                                         ((1.5e11, 0.0, 0.0), (1.5e11 + 1e-3, 0.0, 0.0))])
def test_error_when_positions_coincide(r_sun, r_sc):
    with pytest.raises(ValueError) as exc:
        sunline.sun_heading_B(r_sun, r_sc, (0.0, 0.0, 0.0))
    msg = str(exc.value)
    assert "r_SN_N" in msg and "r_BN_N" in msg and "coincide" in msg
    # 1 km apart at 1 au is still a defined heading
    assert sunline.sun_heading_B((1.5e11, 0.0, 0.0), (1.5e11 - 1e3, 0.0, 0.0), (0.0, 0.0, 0.0)) == (1.0, 0.0, 0.0)


def test_model_parameter_and_input_errors():
    with pytest.raises(ValueError, match="attitude_input = 'euler' must be one of 'mrp', 'quaternion'"):
        sunline.SunlineEphemeris("euler")
    with pytest.raises(ValueError, match="q_BN .* zero"):
        sunline.SunlineEphemeris("quaternion").heading((1.0, 0, 0), (0, 0, 0), q_BN=(0, 0, 0, 0))
    with pytest.raises(ValueError, match="r_SN_N .* finite"):
        sunline.sun_heading_B((math.nan, 0, 0), (0, 0, 0), (0, 0, 0))
    m = sunline.SunlineEphemeris()
    assert m.get_state() == {} and m.set_state({}) is None


# ---- FMU --------------------------------------------------------------------------------
@pytest.fixture(scope="session")
def sunline_fmus(tmp_path_factory):
    import build_fmus

    d = tmp_path_factory.mktemp("sunline_fmus")
    return {p.stem: p for p in (build_fmus.build_fmu(REPO / "fmus" / f"neighbor_{m}.py", d)
                                for m in ("sunline_ephemeris", "rigid_body"))}


def test_fmu_is_valid_with_units_and_dependencies(sunline_fmus):
    path = sunline_fmus["SunlineEphemeris"]
    assert validate_fmu(str(path)) == []
    md = fmpy.read_model_description(str(path))
    v = {x.name: x for x in md.modelVariables}
    assert v["r_SN_N[1]"].unit == "m" and v["sigma_BN[3]"].unit == "1" and v["q_BN[4]"].unit == "1"
    assert v["sun_heading_B[2]"].unit == "1" and v["sun_distance"].unit == "m"
    assert v["attitude_input"].type == "String" and v["attitude_input"].start == "mrp"
    deps = {u.variable.name: {d.name for d in u.dependencies} for u in md.outputs}
    pos = {f"r_SN_N[{i}]" for i in (1, 2, 3)} | {f"r_BN_N[{i}]" for i in (1, 2, 3)}
    att = {f"sigma_BN[{i}]" for i in (1, 2, 3)} | {f"q_BN[{i}]" for i in (1, 2, 3, 4)}
    assert all(deps[f"sun_heading_B[{i}]"] == pos | att for i in (1, 2, 3))
    assert deps["sun_distance"] == pos


@pytest.mark.parametrize("attitude_input", ["mrp", "quaternion"])
def test_fmu_simulates_alone(sunline_fmus, attitude_input):
    # spacecraft on -y, Sun at the origin, 90 deg about z: heading +y in N is +x in B
    start = {"attitude_input": attitude_input, "r_SN_N[1]": 0.0, "r_BN_N[2]": -2.0}
    if attitude_input == "mrp":
        start["sigma_BN[3]"] = TAN_PI_8
    else:
        start.update({"q_BN[3]": -math.sin(math.pi / 4), "q_BN[4]": -math.cos(math.pi / 4)})  # q4 < 0
    r = fmpy.simulate_fmu(str(sunline_fmus["SunlineEphemeris"]), stop_time=0.1, output_interval=0.05,
                          start_values=start)
    for i, e in enumerate((1.0, 0.0, 0.0), 1):
        assert np.abs(r[f"sun_heading_B[{i}]"] - e).max() < 1e-12
    assert np.all(r["sun_distance"] == 2.0)
    # defaults: Sun at 1 au on x, spacecraft at the origin, zero attitude
    r = fmpy.simulate_fmu(str(sunline_fmus["SunlineEphemeris"]), stop_time=0.1, output_interval=0.1)
    assert r["sun_heading_B[1]"][-1] == 1.0 and r["sun_distance"][-1] == 149597870700.0


def test_fmu_refuses_bad_parameter_and_coinciding_positions(sunline_fmus):
    from fmpy.fmi1 import FMICallException

    path = str(sunline_fmus["SunlineEphemeris"])
    for start, words in [({"attitude_input": "euler"}, ["attitude_input = 'euler'", "'mrp', 'quaternion'"]),
                         ({"r_SN_N[1]": 0.0}, ["r_SN_N", "r_BN_N", "coincide"])]:
        messages = []

        def log(component, instance, status, category, message, messages=messages):
            messages.append(message.decode() if isinstance(message, bytes) else message)

        with pytest.raises(FMICallException):
            fmpy.simulate_fmu(path, stop_time=0.1, start_values=start, logger=log, debug_logging=True)
        assert any(all(w in m for w in words) for m in messages), messages


def test_fmu_direct_feedthrough_and_state(sunline_fmus, tmp_path):
    path = sunline_fmus["SunlineEphemeris"]
    md = fmpy.read_model_description(str(path))
    unzip = fmpy.extract(str(path), unzipdir=str(tmp_path / "sun"))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="sunline")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    out = [vr[f"sun_heading_B[{i}]"] for i in (1, 2, 3)]
    q_in = [vr[f"q_BN[{i}]"] for i in (1, 2, 3, 4)]
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.setString([vr["attitude_input"]], ["quaternion"])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        assert fmu.getReal(out) == [1.0, 0.0, 0.0]
        q = rotations.from_axis_angle((0.0, 0.0, 1.0), math.pi / 2)
        fmu.setReal(q_in, list(q))  # read without a step: direct feedthrough
        assert fmu.getReal(out) == pytest.approx([0.0, -1.0, 0.0], abs=1e-15)
        saved = fmu.getFMUstate()
        fmu.doStep(0.0, 0.1)
        fmu.setReal(q_in, [0.0, 0.0, 0.0, 1.0])
        assert fmu.getReal(out) == [1.0, 0.0, 0.0]
        fmu.setFMUstate(saved)  # restores the inputs
        assert fmu.getReal(out) == pytest.approx([0.0, -1.0, 0.0], abs=1e-15)
        fmu.freeFMUstate(saved)
    finally:
        fmu.terminate()
        fmu.freeInstance()


# ---- system -----------------------------------------------------------------------------
@pytest.fixture(scope="session")
def sunline_ssp(sunline_fmus, tmp_path_factory):
    import build_fmus

    fmu_dir = sunline_fmus["SunlineEphemeris"].parent
    return build_fmus.pack_ssp(SYSTEMS / "sunline.ssd", fmu_dir, tmp_path_factory.mktemp("sunline_ssp"))


def test_generated_system_files_are_up_to_date(sunline_fmus, tmp_path):
    from system_ssp.ssp.writer import SystemWriter

    g.generate(SystemWriter(tmp_path, sunline_fmus["SunlineEphemeris"].parent))
    assert (tmp_path / "sunline.ssd").read_text() == (SYSTEMS / "sunline.ssd").read_text()
    for p in (tmp_path / "parameters").glob("*.ssv"):
        assert p.read_text() == (SYSTEMS / "parameters" / p.name).read_text(), p.name


def _rot(axis, theta):
    """Components in B of a vector fixed in N after B turns by +theta about its own axis."""
    c, s = math.cos(theta), math.sin(theta)
    return {"z": np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]),
            "x": np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])}[axis]


@pytest.mark.parametrize("axis, rate, sets", [("z", 0.1, []), ("x", 0.05, ["parameters/sunline_spin_x.ssv"])])
def test_system_heading_turns_with_the_spin(sunline_ssp, axis, rate, sets):
    import system_ssp

    outs = [f"sunline.sun_heading_B[{i}]" for i in (1, 2, 3)] + [f"dynamics.q_BN[{i}]" for i in (1, 2, 3, 4)]
    r = system_ssp.simulate(sunline_ssp, parameter_sets=sets, outputs=outs + ["sunline.sun_distance"])
    assert r.stop_time == pytest.approx(20.0) and len(r.data) == 201
    d_N = (np.array(g.R_SUN_N) - np.array(g.R_SC_N))
    dist = np.linalg.norm(d_N)
    d_N /= dist
    d_B0 = np.array(rotations.attitude_matrix(g.Q0)) @ d_N
    h = np.column_stack([r.data[f"sunline.sun_heading_B[{i}]"] for i in (1, 2, 3)])
    expected = np.array([_rot(axis, rate * t) @ d_B0 for t in r.data["time"]])
    assert np.abs(h - expected).max() < 1e-9
    # the heading really turns (about 2 rad or 1 rad over the run) and only about the spin axis
    k = "xyz".index(axis)
    assert np.ptp(h[:, (k + 1) % 3]) > 0.5 and np.ptp(h[:, k]) < 1e-12
    # at every sample the heading is A(q) d_N of the dynamics' recorded quaternion
    for row, hb in zip(r.data[::20], h[::20]):
        q = [row[f"dynamics.q_BN[{i}]"] for i in (1, 2, 3, 4)]
        assert np.abs(np.array(rotations.attitude_matrix(q)) @ d_N - hb).max() < 1e-12
    assert np.abs(r.data["sunline.sun_distance"] - dist).max() <= 1e-15 * dist


def test_system_mrp_input_ignores_the_quaternion(sunline_ssp):
    import system_ssp

    # attitude_input = "mrp": the connected quaternion is ignored, the zero MRP start value is used
    r = system_ssp.simulate(sunline_ssp, stop_time=1.0, parameters={"sunline.attitude_input": "mrp"},
                            outputs=[f"sunline.sun_heading_B[{i}]" for i in (1, 2, 3)])
    d_N = np.array(g.R_SUN_N) - np.array(g.R_SC_N)
    d_N /= np.linalg.norm(d_N)
    for i in (1, 2, 3):
        assert np.abs(r.data[f"sunline.sun_heading_B[{i}]"] - d_N[i - 1]).max() < 1e-15
