"""NEIGHBOR's power bus: the switched loads, defined once.

The mission manager switches each load on or off (one Boolean output per load), the Power model
sums the powers of the loads that are on (one Boolean input per load, same name), and the
mission system wires each output to the input of the same name. Everything that names a load
(components.mission.power, components.mission.manager, their FMUs and the mission generator)
takes the names, descriptions and powers from `LOADS` here.

Powers are thesis Table 5 (and Appendix I, the code that produced Figure 46):
    microprocessor_nominal    0.022176   STM32L432KC run mode, Appendix I: 84 uA/MHz x 80 MHz x 3.3 V
                                         (Table 5 lists it rounded, 0.0221 W)
    microprocessor_quiescent  9.24e-8    standby 28 nA x 3.3 V (Table 5 and Appendix I)
    uhf_rx                    0.1815     55 mA x 3.3 V
    uhf_tx                    2.64       800 mA x 3.3 V
    horizon_sensor            0.15
    sun_sensor                0.115
    gyro                      0.018
    gps_receiver              1.300
    gps_antenna               0.066      (Appendix I lumps receiver and antenna: GPS_pwr = 1.366 W)
    propulsion                0.5
"""
from typing import NamedTuple


class Load(NamedTuple):
    name: str  # the manager's output and the Power model's input
    description: str  # what draws the power
    power: float  # W, the default
    table5: str  # the value as thesis Table 5 prints it


LOADS = (
    Load("microprocessor_nominal", "STM32L432KC microprocessor in run mode (nominal)", 84e-6 * 80.0 * 3.3, "0.0221 W"),
    Load("microprocessor_quiescent", "STM32L432KC microprocessor in standby (quiescent; clock only)", 28e-9 * 3.3,
         "9.24e-8 W"),
    Load("uhf_rx", "UHF transceiver receiving", 55e-3 * 3.3, "0.1815 W"),
    Load("uhf_tx", "UHF transceiver transmitting", 800e-3 * 3.3, "2.64 W"),
    Load("horizon_sensor", "Horizon sensor", 0.15, "0.15 W"),
    Load("sun_sensor", "Sun sensor", 0.115, "0.115 W"),
    Load("gyro", "Gyroscope", 0.018, "0.018 W"),
    Load("gps_receiver", "GPS receiver", 1.300, "1.300 W"),
    Load("gps_antenna", "GPS antenna", 0.066, "0.066 W"),
    Load("propulsion", "Propulsion system (valves and electronics)", 0.5, "0.5 W"),
)
LOAD_NAMES = tuple(load.name for load in LOADS)
DEFAULT_LOAD_POWER = {load.name: load.power for load in LOADS}
