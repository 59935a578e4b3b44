"""De-orbit propulsion library (thesis Eq. 2-3, 74-79, Table 4) against the thesis' numbers, the
main-thruster model (budget, exact crossing step, state) and the `Propulsion` FMU through FMPy."""
import math

import fmpy
import pytest

from components.core import constants
from components.orbit import propulsion as p
from fmu_helpers import check_declarations, instantiate
from system_ssp.neighbor.validation import assert_reproduces

REL = 0.005  # the brief's 0.5 %

SCENARIOS = [  # (initial km, target km, dV m/s, propellant kg, burn min), thesis Section 3.2
    (420.0, 350.0, 19.84, 0.564, 38.74),
    (475.0, 350.0, 35.18, 0.982, 67.42),
    (525.0, 300.0, 63.21, 1.707, 117.20),
]


@pytest.mark.parametrize("h1, h2, dv, mp, minutes", SCENARIOS)
def test_deorbit_scenarios_match_thesis(h1, h2, dv, mp, minutes):
    s = p.deorbit_scenario(h1 * 1e3, h2 * 1e3, mass0=12.0)
    assert s["delta_v"] == pytest.approx(dv, rel=REL)
    assert s["propellant"] == pytest.approx(mp, rel=REL)
    assert s["burn_time"] / 60.0 == pytest.approx(minutes, rel=REL)
    assert_reproduces(f"deorbit_{h1:.0f}km.delta_v_m_s", s["delta_v"])
    assert_reproduces(f"deorbit_{h1:.0f}km.propellant_kg", s["propellant"])
    # Eq. 2 is the signed form; the rocket equation inverts
    r1, r2 = constants.R_EQ + h1 * 1e3, constants.R_EQ + h2 * 1e3
    assert p.delta_v_eq2(r1, r2) == pytest.approx(-s["delta_v"], rel=1e-12)
    assert p.delta_v_of_propellant(s["propellant"], 12.0) == pytest.approx(s["delta_v"], rel=1e-12)
    # burn time = propellant / (F / (Isp g0)) with F = 4 x 25 mN
    assert s["burn_time"] == pytest.approx(s["propellant"] * 42.0 * 9.81 / 0.1, rel=1e-12)


def test_eq2_against_vis_viva():
    """Eq. 2 is the vis-viva speed change at apoapsis r1 of an r1 x r2 ellipse."""
    mu, r1, r2 = p.MU_EARTH, 6.8e6, 6.7e6
    v_apo = math.sqrt(mu * (2.0 / r1 - 2.0 / (r1 + r2)))
    assert p.delta_v_eq2(r1, r2) == pytest.approx(v_apo - math.sqrt(mu / r1), rel=1e-12)


def test_impulse_to_propellant_eq74():
    """Eq. 74 with the thesis' attitude-control sums: detumble 2.36 g + slew case 3 16.03 g +
    de-orbit tracking 4.75 g = 23.14 g, i.e. the impulse of two 25 mN thrusters for t."""
    assert p.propellant_from_impulse(42.0 * 9.81) == pytest.approx(1.0)
    t_fire = 0.02314 * 42.0 * 9.81 / (2 * 0.025)
    assert p.propellant_from_impulse(2 * 0.025 * t_fire) == pytest.approx(0.02314, rel=1e-12)
    assert 0.564 + 0.02314 == pytest.approx(0.587, abs=0.0005)  # the tank-sizing input


def test_tank_sizing_matches_thesis():
    t = p.tank_sizing(0.587)
    assert t["moles"] == pytest.approx(3.86, rel=REL)
    assert t["volume"] * 1e6 == pytest.approx(376.4, rel=REL)
    assert t["inner_radius"] * 1e2 == pytest.approx(4.48, rel=REL)
    assert t["wall_thickness"] * 1e2 == pytest.approx(0.41, rel=0.015)  # 0.4057 cm, shown rounded
    assert round(t["wall_thickness"] * 1e2, 2) == 0.41
    assert t["outer_radius"] * 1e2 == pytest.approx(4.88, rel=REL)
    assert t["outer_volume"] * 1e6 == pytest.approx(488.2, rel=REL)
    assert t["shell_volume"] * 1e6 == pytest.approx(111.8, rel=REL)
    assert t["shell_mass"] * 1e3 == pytest.approx(301.9, rel=REL)
    assert t["tank_and_propellant_mass"] * 1e3 == pytest.approx(888.9, rel=REL)


TABLE4 = [  # length cm, material volume cm3, mass g, outer volume cm3
    (11.18, 1.52, 12.13, 3.54), (11.18, 1.52, 12.13, 3.54), (11.18, 1.52, 12.13, 3.54), (11.18, 1.52, 12.13, 3.54),
    (10, 1.36, 10.85, 3.17), (5, 0.68, 5.43, 1.58), (10, 1.36, 10.85, 3.17), (5, 0.68, 5.43, 1.58),
    (12.25, 1.66, 13.29, 3.88), (12.25, 1.66, 13.29, 3.88), (12.25, 1.66, 13.29, 3.88), (12.25, 1.66, 13.29, 3.88),
    (20, 2.71, 21.70, 6.33), (15, 2.03, 16.28, 4.75), (20, 2.71, 21.70, 6.33), (15, 2.03, 16.28, 4.75),
]


def test_feed_lines_match_table_4():
    f = p.feed_lines()
    # displayed rounded in the thesis (0.774 mm, 2.4006 mm, 3.175 mm): equal to the shown digits
    assert f["wall_thickness"] * 1e3 == pytest.approx(0.77, abs=0.005)
    assert f["inner_radius"] * 1e3 == pytest.approx(2.4, abs=0.005)
    assert f["outer_radius"] * 1e3 == pytest.approx(3.18, rel=REL)
    assert len(f["lengths"]) == 16
    for i, (length, vm, m, vo) in enumerate(TABLE4):
        assert f["lengths"][i] * 1e2 == pytest.approx(length, abs=0.005), i
        assert f["material_volumes"][i] * 1e6 == pytest.approx(vm, abs=0.005), i
        assert f["masses"][i] * 1e3 == pytest.approx(m, abs=0.005), i
        assert f["outer_volumes"][i] * 1e6 == pytest.approx(vo, abs=0.005), i
    assert f["mass"] * 1e3 == pytest.approx(210.21, rel=REL)
    assert f["mass"] * 1e3 == pytest.approx(210.21, abs=0.005)
    assert f["outer_volume"] * 1e6 == pytest.approx(61.35, abs=0.005)


def test_assembly_mass_matches_thesis():
    a = p.propulsion_assembly_mass(0.587)
    assert a["nozzles"] == pytest.approx(0.64)
    assert a["subtotal"] * 1e3 == pytest.approx(1739.11, rel=REL)
    assert a["manifold"] * 1e3 == pytest.approx(347.82, rel=REL)
    assert a["total"] * 1e3 == pytest.approx(2086.93, rel=REL)
    assert a["total"] == pytest.approx(a["tank_shell"] + 0.587 + a["feed_lines"] + 0.64 + a["manifold"])


def test_library_rejects_bad_values():
    with pytest.raises(ValueError, match="altitude_target"):
        p.deorbit_delta_v(350e3, 420e3)
    with pytest.raises(ValueError, match="mass0"):
        p.propellant_mass(20.0, mass0=0.0)
    with pytest.raises(ValueError, match="isp"):
        p.burn_time(0.5, isp=-1.0)
    with pytest.raises(ValueError, match="propellant"):
        p.tank_sizing(-0.1)
    with pytest.raises(ValueError, match="propellant"):
        p.delta_v_of_propellant(12.0, mass0=12.0)
    with pytest.raises(ValueError, match="thicker"):
        p.feed_lines(pressure=400e6)


# ---- the thruster model ---------------------------------------------------------------------
def test_main_thrusters_burn_to_budget_with_exact_crossing_step():
    budget = p.deorbit_scenario(420e3, 350e3)["propellant"]
    m = p.MainThrusters(mass0=12.0, propellant_budget=budget)
    assert m.force_B(True) == pytest.approx((0.1, 0.0, 0.0))
    assert m.force_B(False) == (0.0, 0.0, 0.0) and m.mdot(False) == 0.0
    assert m.mdot(True) == pytest.approx(0.1 / (42.0 * 9.81))
    m.step(False, 100.0)  # coasting uses nothing
    assert m.used == 0.0 and m.burn_time == 0.0
    h, steps = 7.0, 0  # a step that does not divide the burn time
    while m.burning(True):
        m.step(True, h)
        steps += 1
    t_exact = budget / m.mdot_burning
    assert m.spent and m.used == budget and m.mass == pytest.approx(12.0 - budget, abs=1e-15)
    assert m.burn_time == pytest.approx(t_exact, rel=1e-12)
    assert m.burn_time / 60.0 == pytest.approx(38.74, rel=REL)
    assert steps == math.ceil(t_exact / h)
    assert m.force_B(True) == (0.0, 0.0, 0.0) and m.mdot(True) == 0.0 and m.remaining == 0.0
    m.step(True, 10.0)  # spent: nothing changes
    assert m.burn_time == pytest.approx(t_exact, rel=1e-12)


def test_main_thrusters_axis_state_and_errors():
    m = p.MainThrusters(propellant_budget=0.2, axis_B=(0.0, -1.0, 0.0), n_thrusters=2)
    assert m.force_B(True) == pytest.approx((0.0, -0.05, 0.0))
    m.step(True, 30.0)
    s = m.get_state()
    m.step(True, 30.0)
    after = m.get_state()
    m.set_state(s)
    m.step(True, 30.0)
    assert m.get_state() == after
    assert p.MainThrusters().budget == pytest.approx(0.564, rel=REL)  # default: 420 -> 350 km
    for kwargs, name in (({"propellant_budget": 0.0}, "propellant_budget"),
                         ({"propellant_budget": -1.0}, "propellant_budget"),
                         ({"propellant_budget": 12.0}, "propellant_budget"),
                         ({"mass0": 0.0}, "mass0"), ({"mass0": -3.0}, "mass0"),
                         ({"axis_B": (1.0, 1.0, 0.0)}, "axis_B"), ({"axis_B": (0.0, 0.0)}, "axis_B"),
                         ({"n_thrusters": 0}, "n_thrusters"), ({"isp": float("nan")}, "isp")):
        with pytest.raises(ValueError, match=name):
            p.MainThrusters(**kwargs)
    with pytest.raises(ValueError, match="step size"):
        m.step(True, -1.0)


# ---- FMU ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fmu_path(build_one):
    return build_one("neighbor_propulsion.py")


def test_fmu_declarations(fmu_path):
    deps = check_declarations(fmu_path)
    feed = ["burn_enable"]
    for name in ("F_thrust_B[1]", "F_thrust_B[2]", "F_thrust_B[3]", "mdot", "burning"):
        assert deps[name] == feed
    assert deps["mass"] == ["rcs_propellant"]  # the RCS draws from the same tank
    for name in ("propellant_used", "propellant_remaining", "burn_time", "budget_spent"):
        assert deps[name] == []
    md = fmpy.read_model_description(str(fmu_path))
    units = {v.name: v.unit for v in md.modelVariables}
    assert units["F_thrust_B[1]"] == "N" and units["mdot"] == "kg/s" and units["mass"] == "kg"


def test_fmu_burn_through_fmpy(fmu_path, tmp_path):
    budget = 0.05
    fmu, vr = instantiate(fmu_path, tmp_path, "propulsion")
    try:
        fmu.setReal([vr["propellant_budget"]], [budget])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        real = lambda *names: fmu.getReal([vr[n] for n in names])  # noqa: E731
        assert real("F_thrust_B[1]", "mdot", "mass") == [0.0, 0.0, 12.0]
        fmu.setBoolean([vr["burn_enable"]], [True])
        assert real("F_thrust_B[1]")[0] == pytest.approx(0.1) and fmu.getBoolean([vr["burning"]]) == [True]
        t, h = 0.0, 0.5
        saved = None
        while not fmu.getBoolean([vr["budget_spent"]])[0]:
            fmu.doStep(t, h)
            t += h
            if saved is None and t >= 60.0:
                saved, at_save = fmu.getFMUstate(), real("mass", "burn_time")
        t_exact = budget * 42.0 * 9.81 / 0.1
        assert real("burn_time")[0] == pytest.approx(t_exact, rel=1e-12)
        assert real("mass", "propellant_used", "propellant_remaining") == pytest.approx([12.0 - budget, budget, 0.0])
        assert real("F_thrust_B[1]", "mdot") == [0.0, 0.0] and fmu.getBoolean([vr["burning"]]) == [False]
        fmu.setFMUstate(saved)
        assert real("mass", "burn_time") == at_save and fmu.getBoolean([vr["budget_spent"]]) == [False]
        fmu.freeFMUstate(saved)
    finally:
        fmu.terminate()
        fmu.freeInstance()


def test_fmu_rejects_budget_above_mass(fmu_path):
    with pytest.raises(Exception):
        fmpy.simulate_fmu(str(fmu_path), stop_time=1.0, start_values={"propellant_budget": 13.0})


def test_the_rcs_draws_from_the_same_tank():
    m = p.MainThrusters(mass0=12.0, propellant_budget=0.5)
    m.step(True, 60.0)
    assert m.mass_with(0.01) == pytest.approx(12.0 - m.used - 0.01, rel=1e-15)
    for bad in (-0.001, math.nan, 12.0):
        with pytest.raises(ValueError, match="rcs_propellant"):
            m.mass_with(bad)


def test_off_pulsed_thrust_is_taken_out_of_the_next_step_and_the_burn_lasts_longer():
    budget = 0.05
    full, pulsed = p.MainThrusters(mass0=12.0, propellant_budget=budget), p.MainThrusters(mass0=12.0,
                                                                                          propellant_budget=budget)
    h, off, steps = 0.5, 0.0, 0
    while pulsed.burning(True):
        pulsed.step(True, h, off)
        steps += 1
        if steps > 1 and pulsed.burning(True):  # one of four thrusters off 25 % of each step: 1/16 of the thrust
            assert pulsed.on_fraction == pytest.approx(1.0 - 0.25 / 4.0)
            assert pulsed.force_B(True)[0] == pytest.approx(0.1 * pulsed.on_fraction)
            assert pulsed.mdot(True) == pytest.approx(full.mdot_burning * pulsed.on_fraction)
        off += 0.25 * h
    t_full = budget / full.mdot_burning
    assert pulsed.used == budget and pulsed.burn_time == pytest.approx(t_full / (1 - 1 / 16.0), rel=1e-3)
    with pytest.raises(ValueError, match="off_time"):
        pulsed.step(True, h, off - 1.0)  # a running total never falls
    restored = p.MainThrusters(mass0=12.0, propellant_budget=budget)
    restored.set_state(pulsed.get_state())
    assert (restored.on_fraction, restored.off_seen, restored.last_h) == (pulsed.on_fraction, pulsed.off_seen, h)
