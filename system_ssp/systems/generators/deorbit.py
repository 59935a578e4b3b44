"""Write the de-orbit systems (.ssd) and their parameter files (.ssv).

    python build_fmus.py && python system_ssp/systems/generate_deorbit.py

Two systems with the same wiring, differing in one component (a fidelity swap):
- `deorbit`:          orbit = Orbit (Cowell: J2..J6 zonal gravity, drag at every integrator
                      stage, adaptive DOP853 inside each communication step);
- `deorbit_lifetime`: orbit = OrbitAveraged (mean elements, orbit-averaged drag, J2 secular
                      drift), fast enough for century-long lifetimes.
Both: propulsion (the main de-orbit thrusters, burning from t = 0 until the scenario's
propellant budget is spent, thrust along -v through orbit.retrograde since no attitude is
simulated). The orbit evaluates the density itself, at every integrator stage (its `density`
output is the recorded signal): a separate Atmosphere FMU here would only be sampled at the
communication points and change nothing, so it is not in these systems (it is in acs_modes and
sun_eclipse). The run stops at orbit.reentered (geodetic altitude, or mean perigee for the
averaged model, below 250 km: the thesis' re-entry point).

Steps (nc:Schedule): 0.5 s while propulsion.burning (the thesis' manoeuvre step, Section 3.2),
otherwise 1 h (Cowell) or 1 day (averaged). The orbit FMUs integrate adaptively inside a step,
so the coast step only sets how often outputs are sampled and re-entry is tested.

Parameter files (component-level, the first binding of each component):
- deorbit_orbit.ssv       epoch 2023-01-01, Table 3 elements for 420 km, Cd 2.2, 0.02 m^2 (Table 2),
                          Jacchia-Roberts driven by the bundled CSSI space-weather file;
- deorbit_propulsion.ssv  4 x 25 mN, Isp 42 s, g0 9.81, 12 kg, the 420 km propellant budget.
Scenario files (names component.variable), one per thesis case, with and without the burn:
- deorbit_420km.ssv, deorbit_420km_no_burn.ssv, deorbit_475km..., deorbit_525km...:
  initial semi-major axis R_eq + h0 and, with the burn, the propellant of Eq. 2-3 for the
  scenario's target perigee (350, 350, 300 km). Without the burn, burn_enable stays false
  (the host alone, 12 kg).
"""
from components.mission.neighbor import (DEFAULT_SCENARIO, DEORBIT_SYSTEMS, ORBIT as HOST_ORBIT, SCENARIOS,
                                         SPACECRAFT, scenario_set)
from components.orbit import propulsion
from components.core.constants import R_EQ

from .from_spec import write_system

KM = 1000.0
BASE = SCENARIOS[DEFAULT_SCENARIO]  # the component-level files start from it
ORBIT = {"epoch": HOST_ORBIT.deorbit_epoch, "sma0": R_EQ + BASE.altitude_km * KM, "ecc0": 0.0,
         "inc0": HOST_ORBIT.inclination, "raan0": 0.0, "argp0": 0.0, "ta0": 0.0, "Cd": SPACECRAFT.Cd,
         "area": SPACECRAFT.drag_area, "reentry_altitude": HOST_ORBIT.reentry_altitude_km * KM,
         "density_model": HOST_ORBIT.density_model, "space_weather_file": "", "use_constant_space_weather": False}


def scenario(name, burn):
    params = {"orbit.sma0": R_EQ + SCENARIOS[name].altitude_km * KM, "propulsion.burn_enable": burn}
    if burn:
        params["propulsion.propellant_budget"] = propulsion.mission_scenario(name)["propellant"]
    return params


def generate(writer):
    orbit = dict(ORBIT, retrograde=True)
    writer.ssv("deorbit_orbit",
               "Host orbit and drag (thesis Tables 2-3, start 2023-01-01; Jacchia-Roberts with the bundled CSSI "
               "space weather); retrograde thrust since no attitude is simulated", orbit)
    dv = propulsion.mission_scenario(BASE.name)
    writer.ssv("deorbit_propulsion",
               f"Main de-orbit thrusters ({propulsion.N_THRUSTERS} x {propulsion.THRUST_PER_THRUSTER * 1e3:g} mN, "
               f"Isp {propulsion.ISP:g} s, g0 {propulsion.G0:g}; thesis Section 3.2, Appendix A), "
               f"{propulsion.MASS0:g} kg, the {BASE.altitude_km:g} km -> {BASE.target_perigee_km:g} km propellant "
               "budget (Eq. 2-3)",
               {"thrust_per_thruster": propulsion.THRUST_PER_THRUSTER, "n_thrusters": propulsion.N_THRUSTERS,
               "isp": propulsion.ISP, "g0": propulsion.G0, "mass0": propulsion.MASS0,
               "propellant_budget": dv["propellant"]})
    cowell, averaged = DEORBIT_SYSTEMS["cowell"], DEORBIT_SYSTEMS["averaged"]
    for s in SCENARIOS.values():
        h0, target = s.altitude_km, s.target_perigee_km
        writer.ssv(scenario_set(cowell, s.name),
                   f"Thesis scenario {h0:g} km -> {target:g} km perigee, with the NEIGHBOR burn",
                   scenario(s.name, True))
        writer.ssv(scenario_set(cowell, s.name, burn=False),
                   f"Thesis scenario {h0:g} km without NEIGHBOR (host alone, {SPACECRAFT.mass:g} kg)",
                   scenario(s.name, False))
    # the lifetime system's scenario files are the same files under its name
    for name in SCENARIOS:
        for burn in (True, False):
            writer.ssv_copy(scenario_set(cowell, name, burn), scenario_set(averaged, name, burn))
    for name in DEORBIT_SYSTEMS.values():
        write_system(writer, name)
