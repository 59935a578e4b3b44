"""FMU `Propulsion` (instance `propulsion`): NEIGHBOR's de-orbit thrusters (4 x 25 mN, Isp 42 s).

Wraps components.orbit.propulsion.MainThrusters. While `burn_enable` is true and the propellant budget
is not spent, `F_thrust_B` = n F axis_B is the force ON THE SPACECRAFT in the body frame (the
exhaust leaves along -axis_B) and the mass falls at mdot = n F / (Isp g0). The burn stops when
m0 - m >= propellant_budget (thesis Appendix F); the step that crosses the budget burns only for
the remaining fraction (mass and burn_time exact). Thrust, flow and `burning` depend directly on
`burn_enable` and are held by the master over a step (zero-order hold), so in the crossing step
the orbit sees full thrust for the whole step, and zero from the next one. `mass`,
`propellant_used`, `propellant_remaining`, `burn_time` and `budget_spent` are states at the
communication point. The orbit FMUs take `mass` and `F_thrust_B` as inputs. `axial_off_time`
(appended last) is the thruster FMU's running total of off-pulsed thruster-seconds: the thrust
it took away since the previous step is taken out of this step's thrust and flow (`on_fraction`).
"""
from neighbor_fmu_support import NeighborSlave

from components.orbit import propulsion

_DEFAULT_BUDGET = propulsion.mission_scenario()["propellant"]


class Propulsion(NeighborSlave):
    description = ("De-orbit propulsion: thrust force in B, propellant flow and spacecraft mass of the main "
                   "thrusters (thesis Eq. 3, Appendix F), burning until the propellant budget is spent")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("thrust_per_thruster", propulsion.THRUST_PER_THRUSTER, "N", "Thrust of one thruster (> 0)")
        self.parameter("n_thrusters", propulsion.N_THRUSTERS, None,
                       "Number of de-orbit thrusters fired together (>= 1)", int)
        self.parameter("isp", propulsion.ISP, "s", "Specific impulse (> 0)")
        self.parameter("g0", propulsion.G0, "m/s2", "Standard gravity in the rocket equation (> 0)")
        self.parameter("mass0", propulsion.MASS0, "kg", "Initial total spacecraft mass (> 0)")
        self.parameter("propellant_budget", _DEFAULT_BUDGET, "kg",
                       "Propellant the burn may use, in (0, mass0); default the 420 -> 350 km scenario "
                       "(Eq. 2-3, 0.564 kg); components.orbit.propulsion.deorbit_scenario computes others")
        self.parameter_array("axis_B", [1.0, 0.0, 0.0], "1",
                             "Unit direction in B of the thrust force on the spacecraft (exhaust along -axis_B)")
        self.input("burn_enable", False, None, "Burn command: thrusters fire while true and propellant remains",
                   bool)
        deps = ["burn_enable"]
        self.output_array("F_thrust_B", 3, lambda: self.model.force_B(self.input_value("burn_enable")), "N",
                          "Thrust force on the spacecraft in B (zero when not burning)", depends_on=deps)
        self.output("mdot", lambda: self.model.mdot(self.input_value("burn_enable")), "kg/s",
                    "Propellant mass flow (>= 0; zero when not burning)", depends_on=deps)
        self.output("burning", lambda: self.model.burning(self.input_value("burn_enable")), None,
                    "True while burn_enable is true and the budget is not spent", bool, depends_on=deps)
        self.output("mass", lambda: self.model.mass_with(self.input_value("rcs_propellant")), "kg",
                    "Current total spacecraft mass: mass0 - propellant_used - rcs_propellant (one tank)",
                    depends_on=["rcs_propellant"])
        self.output("propellant_used", lambda: self.model.used, "kg", "Propellant used so far")
        self.output("propellant_remaining", lambda: self.model.remaining, "kg",
                    "Propellant budget not yet used")
        self.output("burn_time", lambda: self.model.burn_time, "s", "Accumulated burn time")
        self.output("budget_spent", lambda: self.model.spent, None,
                    "True once the propellant budget is used up (thrust stays off)", bool)
        self.input("rcs_propellant", 0.0, "kg", "Propellant the RCS thrusters have drawn from the same tank (>= 0), "
                   "from the thruster FMU; lowers the mass")
        self.input("axial_off_time", 0.0, "s", "Running total of the time these thrusters were switched off for "
                   "attitude control (off-pulsing), summed over the thrusters, from the thruster FMU")
        self.output("on_fraction", lambda: self.model.on_fraction, "1",
                    "Fraction of the thrust and flow applied over the current step (1 unless off-pulsed)")
        self.share_values(outputs=False)

    def build_model(self):
        v = self.values
        return propulsion.MainThrusters(v["thrust_per_thruster"], v["n_thrusters"], v["isp"], v["g0"], v["mass0"],
                                        v["propellant_budget"], self.vector("axis_B", 3))

    def do_step(self, current_time, step_size):
        self.model.step(self.input_value("burn_enable"), step_size, self.input_value("axial_off_time"))
        return True
