"""The second reference spacecraft: a 3U CubeSat with the commonest CubeSat ADCS, defined once
(the NEIGHBOR mission's counterpart, components.mission.neighbor).

This first part defines its mass properties, its four reaction wheels in a pyramid and the
MRP feedback gains of its pointing modes; the shipped system cubesat_3u_pointing flies them
(system_ssp/systems/generators/cubesat_3u.py writes its parameter sets from these values). The
coils, sensors, solar panels, battery and the day-long mission follow (issue 57).

Plain data (no models, no FMI): it imports only the standard library and `components.core`.
"""
from dataclasses import dataclass
import math
from typing import Tuple

RPM = 2.0 * math.pi / 60.0
PYRAMID_ELEVATION = math.atan(1.0 / math.sqrt(2.0))  # 35.26 deg: the same capability on every body axis


@dataclass(frozen=True)
class Spacecraft:
    """A 4 kg 3U (0.1 x 0.1 x 0.34 m, long axis along body z), mass not quite centred: the
    inertia of the uniform box plus small products of inertia, about the centre of mass, with
    the wheels' spin inertia included (the whole spacecraft's)."""
    mass: float = 4.0  # kg
    size: Tuple[float, float, float] = (0.10, 0.10, 0.34)  # m, along body x, y, z
    inertia_B: Tuple[Tuple[float, float, float], ...] = ((0.0420, 0.0004, -0.0003),
                                                         (0.0004, 0.0418, 0.0002),
                                                         (-0.0003, 0.0002, 0.0071))  # kg.m2


@dataclass(frozen=True)
class Wheels:
    """Four wheels of the 10 mN.m.s, 1 mN.m, 6000 rpm class (J = 1.5e-5 kg.m2) in a pyramid about
    +z: each spin axis 35.26 deg above the xy plane, at azimuths 45, 135, 225, 315 deg (the spin
    axes: components.acs.reaction_wheel_array.pyramid_axes(elevation, count, azimuth0))."""
    count: int = 4
    elevation: float = PYRAMID_ELEVATION  # rad
    azimuth0: float = math.radians(45.0)  # rad
    J_s: float = 1.5e-5  # kg.m2
    max_torque: float = 1.0e-3  # N.m
    max_speed: float = 6000.0 * RPM  # rad/s
    speed0: Tuple[float, ...] = (100.0, -150.0, 200.0, 50.0)  # rad/s at the start of the pointing systems




@dataclass(frozen=True)
class PointingControl:
    """MRP feedback gains (Schaub's law, Basilisk's mrpFeedback) at 10 Hz: about 20 s to settle
    a large slew within the wheels' 1 mN.m, no integral term."""
    step: float = 0.1  # s
    K: float = 0.015  # N.m
    P: float = 0.06  # N.m.s
    sigma_R0N: Tuple[float, float, float] = (0.1, 0.2, -0.3)  # the inertial mode's reference attitude (MRP)


SPACECRAFT = Spacecraft()
WHEELS = Wheels()
POINTING = PointingControl()
ORBIT = {"altitude": 500e3, "inclination": math.radians(97.4), "raan": 0.0, "arg_latitude0": 0.0}
# a tumble after the detumble hands over: 1.6 deg/s, the wheels at WHEELS.speed0
_Q = (0.3, -0.2, 0.5, 0.78)
INITIAL_ATTITUDE = tuple(x / math.sqrt(sum(y * y for y in _Q)) for x in _Q)  # q_BN, scalar last: 144 deg off R
INITIAL_RATE = (0.02, -0.015, 0.01)  # rad/s
