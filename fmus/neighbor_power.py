"""FMU `Power` (instance `power`): NEIGHBOR's battery (one LG HG2 cell, 10.8 Wh = 38880 J)
drained by the components the mission manager switches on.

Wraps components.mission.power.PowerSystem (see its docstring for the load powers, Table 5 vs Table 6
vs Appendix I, and the exact integration). Inputs: one Boolean per load (held over a step)
`solar_power` (W, default 0: NEIGHBOR has no panels; SolarArrays or a host may charge it) and
`other_load_power` (W, default 0: loads of another spacecraft outside the switch list). `load_power`
depends directly on the Booleans and other_load_power; energy, state_of_charge, energy_used and empty are states.
"""
from neighbor_fmu_support import NeighborSlave

from components.mission import power
from components.mission.power_bus import LOADS, LOAD_NAMES


class Power(NeighborSlave):
    description = ("NEIGHBOR power supply: LG HG2 Li-ion cell (3.0 Ah, 3.6 V, 38880 J) drained by the switched "
                   "loads of thesis Table 5 (Appendix I duty model); stored energy exact over any step")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("capacity", power.CELL_CAPACITY, "J",
                       "Battery capacity, > 0 (default 3.0 Ah x 3.6 V = 10.8 Wh = 38880 J)")
        self.parameter("initial_state_of_charge", 1.0, "1",
                       "Initial stored energy as a fraction of capacity, in [0, 1]")
        self.parameter("base_load", 0.0, "W", "Always-on load beyond the switched ones, >= 0 (another spacecraft's "
                       "bus; default 0, NEIGHBOR's loads are all switched)")
        for load in LOADS:
            self.parameter(f"power_{load.name}", load.power, "W", f"Power drawn by: {load.description} (>= 0)")
        for load in LOADS:
            self.input(load.name, False, None, f"On/off: {load.description}", bool)
        self.input("solar_power", 0.0, "W", "Charging power from solar arrays or a host (>= 0; default 0, "
                   "NEIGHBOR has no panels)")
        other = self.input("other_load_power", 0.0, "W", "Power of loads outside the switch list (another "
                           "spacecraft's avionics, its wheels' electrical power), >= 0; default 0")
        m = lambda: self.model  # noqa: E731
        self.output("energy", lambda: m().energy, "J", "Stored battery energy, in [0, capacity]")
        self.output("state_of_charge", lambda: m().state_of_charge, "1", "Stored energy / capacity")
        self.output("load_power", lambda: m().load_power(self._switches()) + self._other_load(), "W",
                    "Total power of the loads switched on plus base_load and other_load_power",
                    depends_on=list(LOAD_NAMES) + [other])
        self.output("energy_used", lambda: m().energy_used, "J",
                    "Cumulative energy delivered to the loads since the start")
        self.output("empty", lambda: m().empty, None, "True when the battery is empty (energy 0)", bool)

    def _other_load(self):
        return self.values["base_load"] + self.values["other_load_power"]

    def _switches(self):
        return {name: self.values[name] for name in LOAD_NAMES}

    def build_model(self):
        v = self.values
        power._number("base_load", v["base_load"], "W")
        return power.PowerSystem(v["capacity"], v["initial_state_of_charge"],
                                 {name: v[f"power_{name}"] for name in LOAD_NAMES})

    def do_step(self, current_time, step_size):
        self.model.step(self._switches(), step_size, self.values["solar_power"], self._other_load())
        return True
