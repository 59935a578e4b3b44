"""The second reference spacecraft: a 3U CubeSat with the commonest CubeSat ADCS, defined once
(the NEIGHBOR mission's counterpart, components.mission.neighbor).

It defines its mass properties, its four reaction wheels in a pyramid, its three torque rods
and the gains of its laws (pointing, B-dot, momentum dumping), its solar panels and battery;
the shipped systems cubesat_3u_* fly them (system_ssp/systems/generators/cubesat_3u.py writes
their parameter sets from these values).

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
class Coils:
    """Three magnetic torque rods on the body axes (0.2 A.m2 each, the CubeSat torque-rod class):
    about 6 uN.m in the 30 uT of a 500 km orbit. The three-axis B-dot gain saturates them above
    ~0.2 deg/s; the dumping gain asks -1e-3/s times the wheels' momentum (5 uN.m for 5 mN.m.s,
    the coils' authority)."""
    max_dipole: float = 0.2  # A.m2 per axis
    detumble_gain: float = 2.0e-3  # N.m.s (components.acs.magnetic_control.BdotDetumble)
    dumping_gain: float = 1.0e-3  # 1/s (components.acs.magnetic_control.MomentumDumping)


@dataclass(frozen=True)
class PointingControl:
    """MRP feedback gains (Schaub's law, Basilisk's mrpFeedback) at 10 Hz: about 20 s to settle
    a large slew within the wheels' 1 mN.m, no integral term."""
    step: float = 0.1  # s
    K: float = 0.015  # N.m
    P: float = 0.06  # N.m.s
    sigma_R0N: Tuple[float, float, float] = (0.1, 0.2, -0.3)  # the inertial mode's reference attitude (MRP)


@dataclass(frozen=True)
class Facet:
    """An outer face for the drag and solar-pressure disturbances and the solar cells on it:
    outward (cell-side) normal and centre in B (m, from the centre of mass), area (m2), specular
    and diffuse reflection coefficients, and the cells' area and efficiency (0: no cells)."""
    name: str
    normal_B: Tuple[float, float, float]
    area: float
    centre_B: Tuple[float, float, float]
    specular: float
    diffuse: float
    cell_area: float = 0.0
    cell_efficiency: float = 0.0


def _facets() -> Tuple[Facet, ...]:
    """The 3U box (0.1 x 0.1 x 0.34 m, centre of mass 5 mm off the centre towards -z) with cells on
    its four long faces (0.024 m2 each, triple-junction cells at 28 % less 10 % for the cover
    glass and wiring: 0.25) and two deployed wings, 0.3 x 0.1 m each (0.027 m2 of cells at 28 %),
    hinged at the +-x edges of the +z end and opened flat facing +z (the zenith in nadir
    pointing). The faces' optics are assumed (cells: specular 0.05, diffuse 0.20; the wings'
    backs bare)."""
    cells, bare = (0.05, 0.20), (0.20, 0.40)
    dz = 0.005  # m: the centre of the box above the centre of mass
    long_faces = [Facet(f"{'+-'[k % 2]}{'xy'[k // 2]}", tuple(float(v) for v in n), 0.1 * 0.34,
                        (0.05 * n[0], 0.05 * n[1], dz), *cells, 0.024, 0.25)
                  for k, n in enumerate(((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)))]
    ends = [Facet("+z", (0.0, 0.0, 1.0), 0.01, (0.0, 0.0, 0.17 + dz), *bare),
            Facet("-z", (0.0, 0.0, -1.0), 0.01, (0.0, 0.0, -0.17 + dz), *bare)]
    wings = [Facet(f"wing {side}x", (0.0, 0.0, 1.0), 0.03, (sign * 0.2, 0.0, 0.17 + dz), *cells,
                   0.027, 0.28)
             for side, sign in (("+", 1.0), ("-", -1.0))]
    backs = [Facet(f"wing {side}x back", (0.0, 0.0, -1.0), 0.03, (sign * 0.2, 0.0, 0.17 + dz), *bare)
             for side, sign in (("+", 1.0), ("-", -1.0))]
    return tuple(long_faces + ends + wings + backs)


@dataclass(frozen=True)
class Power:
    """Two 18650 Li-ion cells in series (2 x 3.0 Ah x 3.6 V = 21.6 Wh), 80 % charged at the start;
    the bus and payload draw 2 W always, each wheel's electronics 0.15 W plus its motor at 60 %
    efficiency."""
    capacity: float = 2 * 3.0 * 3.6 * 3600.0  # J
    initial_state_of_charge: float = 0.8
    base_load: float = 2.0  # W
    wheel_base_power: float = 0.15  # W per wheel
    wheel_motor_efficiency: float = 0.6


@dataclass(frozen=True)
class DayPointing:
    """The day-long nadir pointing at 1 Hz: MRP gains for the smallest axis (J_z = 0.0071 kg.m2,
    P h / J_z = 0.7 at h = 1 s), damping 1.1 about x and y, a 20 s time constant; the field from
    the magnetometer feeds the momentum dumping."""
    step: float = 1.0  # s
    K: float = 5.0e-4  # N.m
    P: float = 5.0e-3  # N.m.s
    duration: float = 86400.0  # s


@dataclass(frozen=True)
class Sensors:
    """The ADCS sensors of the day after separation: a MEMS gyro sampled at 1 Hz (white noise
    1e-4 rad/s per sample, a 10 deg/h bias on each axis), a horizon sensor (0.25 deg), six coarse
    Sun sensors on the faces (0.5 % signal noise, 80 deg field of view; the estimator takes their
    heading as good to 3 deg) and the magnetometer. The pointing mode flies on the estimate while
    the filter's largest 1-sigma is within 5 deg: in the eclipses (the nadir alone) it grows to
    about 2 deg, so a 2 deg limit dropped the spacecraft into Sun-safe at every eclipse."""
    gyro_sigma: float = 1.0e-4  # rad/s per 1 s sample
    gyro_bias: Tuple[float, float, float] = tuple(math.radians(10.0) / 3600.0 * s for s in (1.0, -1.0, 0.6))
    horizon_sigma: float = math.radians(0.25)  # rad
    coarse_sun_sigma: float = math.radians(3.0)  # rad, as the estimator weighs the coarse heading
    attitude_valid_sigma: float = math.radians(5.0)  # rad: the estimate the pointing mode flies on


@dataclass(frozen=True)
class ModeSequence:
    """Detumble until the gyro reads below 1.5 deg/s for a minute (the wheels absorb the rest:
    0.042 kg.m2 at 1.5 deg/s is 1.1 mN.m.s of their 10 each), Sun-safe with +z (the wings) at the
    Sun until the Sun stays within 10 deg and the estimate is valid for a minute, then nadir;
    back to detumble above 5 deg/s."""
    detumble_exit_rate: float = math.radians(1.5)  # rad/s
    detumble_entry_rate: float = math.radians(5.0)  # rad/s
    sun_safe_exit_angle: float = math.radians(10.0)  # rad
    hold_time: float = 60.0  # s
    sun_axis_B: Tuple[float, float, float] = (0.0, 0.0, 1.0)
    duration: float = 86400.0  # s


SPACECRAFT = Spacecraft()
WHEELS = Wheels()
COILS = Coils()
POINTING = PointingControl()
FACETS = _facets()
RESIDUAL_DIPOLE_B = (0.002, -0.001, 0.003)  # A.m2: assumed, the class measured on 3U CubeSats
POWER = Power()
DAY = DayPointing()
SENSORS = Sensors()
MODES = ModeSequence()
_TUMBLE_AXIS = (0.6, -0.5, 0.62)
# rad/s: 10 deg/s after the deployer, about an axis off all three principal ones
DETUMBLE_RATE = tuple(math.radians(10.0) * x / math.sqrt(sum(y * y for y in _TUMBLE_AXIS)) for x in _TUMBLE_AXIS)
# Sun-synchronous 500 km, ascending node at 10:30 local time at the default epoch (2023-01-01,
# the Sun's right ascension 281 deg): 35 min eclipses an orbit
ORBIT = {"altitude": 500e3, "inclination": math.radians(97.4), "raan": math.radians(258.5), "arg_latitude0": 0.0}
# a tumble after the detumble hands over: 1.6 deg/s, the wheels at WHEELS.speed0
_Q = (0.3, -0.2, 0.5, 0.78)
INITIAL_ATTITUDE = tuple(x / math.sqrt(sum(y * y for y in _Q)) for x in _Q)  # q_BN, scalar last: 144 deg off R
INITIAL_RATE = (0.02, -0.015, 0.01)  # rad/s
