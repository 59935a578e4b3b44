"""NEIGHBOR's power supply (the NEIGHBOR thesis, section 3.5, Tables 5-6, Figure 46, Appendix I):
one LG HG2 Li-ion cell drained by the components that are switched on.

Battery: 3.0 Ah at 3.6 V = 10.8 Wh = 38880 J (`CELL_CAPACITY`, the `capacity` parameter).
Energy on interfaces is in J (docs/conventions.md); 1 Wh = 3600 J.

Loads: one on/off switch each, named, described and powered (Table 5) in
components.mission.power_bus (the names are the FMU's Boolean inputs).

Sources and where they disagree (we follow Table 5 for the components and Appendix I, the code
that produced Figure 46, for how they combine):
- The text of 3.5 rounds some values (UHF 2.82 W, sun sensor 0.12 W, gyroscope 0.02 W, GPS
  1.36 W); Table 5 and Appendix I agree on the values above.
- Appendix I's comment says the processor "runs at 41 microAmps per MHz", its code uses
  84e-6 A/MHz (the STM32L432KC run-mode figure); 84e-6 x 80 x 3.3 = 0.022176 W is Table 5's
  0.0221 W, so we use the code's value.
- Table 6's power column is shifted by one row against its actions. Appendix I gives:
  final contact (processor + UHF Rx + Tx) 2.8437 W (Table 6 puts 2.84 on "Awaiting Final
  Contact"); attitude determination (processor + horizon + sun + gyro + GPS) 1.6712 W
  (Table 6: 1.67 on "Final Contact"); attitude control and the de-orbit burn (the same plus
  propulsion) 2.1712 W (Table 6: 2.17 on "Attitude Determination" and "Attitude Control
  Maneuvers"); monitoring out of contact (processor quiescent) 9.24e-8 W (Table 6: on
  "De-orbit Maneuver"); monitoring contact (processor + UHF Rx + Tx + GPS) 4.2097 W (Table 6:
  4.21 on "Microprocessor Quiescent State"). We follow Appendix I; which switches are on in
  each mode is the mission manager's business, this model only sums what is on.

Another spacecraft's loads that are not on NEIGHBOR's switch list (its avionics, its reaction
wheels' electrical power) come in as `other_load_power` (W), added to the switched loads.

Integration: over a step the switches, `solar_power` and `other_load_power` are held, so the net
power P = solar_power - load_power is constant and the stored energy E(t) = E0 + P t is exact until
it reaches 0 or the capacity, where it is clamped (the instant is computed inside the step, so
the result does not depend on the step size). `energy_used` is the energy delivered to the
loads: the full load while the battery can supply it; with the battery empty the loads get only
the solar power (if any); charge beyond the capacity is shed.
"""
import math

from .power_bus import DEFAULT_LOAD_POWER, LOAD_NAMES

CELL_CAPACITY = 3.0 * 3.6 * 3600.0  # J: LG HG2, 3.0 Ah at 3.6 V = 10.8 Wh
WH = 3600.0  # J per Wh

def _number(name, value, unit, low=0.0, high=math.inf):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} must be a number in [{low}, {high}] {unit}") from None
    if isinstance(value, bool) or not (math.isfinite(v) and low <= v <= high):
        raise ValueError(f"{name} = {value!r} must be a finite number in [{low}, {high}] {unit}")
    return v


class PowerSystem:
    """Battery energy bookkeeping for NEIGHBOR's switched loads.

    PowerSystem(capacity=38880 J, initial_state_of_charge=1, load_power={name: W, ...})
    `load_power` overrides entries of DEFAULT_LOAD_POWER (unknown names are an error)."""

    def __init__(self, capacity=CELL_CAPACITY, initial_state_of_charge=1.0, load_power=None):
        self.capacity = _number("capacity", capacity, "J", 0.0)
        if self.capacity <= 0.0:
            raise ValueError(f"capacity = {capacity!r} must be a finite number > 0 J")
        soc0 = _number("initial_state_of_charge", initial_state_of_charge, "(fraction of capacity)", 0.0, 1.0)
        self.powers = dict(DEFAULT_LOAD_POWER)
        for name, value in (load_power or {}).items():
            if name not in self.powers:
                raise ValueError(f"unknown load {name!r}; loads are {', '.join(LOAD_NAMES)}")
            self.powers[name] = _number(f"power_{name}", value, "W")
        self.energy = soc0 * self.capacity
        self.energy_used = 0.0

    # ---- loads --------------------------------------------------------------------------
    def load_power(self, on):
        """Total power (W) of the loads switched on; `on` maps load names to booleans (missing
        names are off) or is an iterable of the names that are on."""
        if not hasattr(on, "items"):
            on = {name: True for name in on}
        total = 0.0
        for name, state in on.items():
            if name not in self.powers:
                raise ValueError(f"unknown load {name!r}; loads are {', '.join(LOAD_NAMES)}")
            if state:
                total += self.powers[name]
        return total

    # ---- state --------------------------------------------------------------------------
    @property
    def state_of_charge(self):
        return self.energy / self.capacity

    @property
    def empty(self):
        return self.energy <= 0.0

    def step(self, on, dt, solar_power=0.0, other_load_power=0.0):
        """Advance by dt seconds with the switches `on`, `solar_power` (W) and the loads outside the
        switch list, `other_load_power` (W), held."""
        dt = _number("step size", dt, "s")
        solar = _number("solar_power", solar_power, "W")
        load = self.load_power(on) + _number("other_load_power", other_load_power, "W")
        net = solar - load
        e0 = self.energy
        if net < 0.0:
            t_empty = e0 / -net
            if dt <= t_empty:
                self.energy = e0 + net * dt
                self.energy_used += load * dt
            else:  # empty inside the step: from then on the loads get only the solar power
                self.energy = 0.0
                self.energy_used += load * t_empty + solar * (dt - t_empty)
        else:
            self.energy = min(self.capacity, e0 + net * dt)
            self.energy_used += load * dt
        if self.energy < 0.0:  # rounding
            self.energy = 0.0

    def get_state(self):
        return {"energy": self.energy, "energy_used": self.energy_used}

    def set_state(self, state):
        self.energy = float(state["energy"])
        self.energy_used = float(state["energy_used"])
