"""FMU `GroundStation` (instance `ground`): contact geometry between the UIUC ground station and
the spacecraft, and the ground's final de-orbit confirmation.

Wraps components.mission.ground_station.GroundStation (WGS-84 station, Earth rotation by GMST). Every
output depends directly on the input r_BN_N (and on the time the model keeps: the start time at
initialization, t + h after do_step(t, h)).
"""

from neighbor_fmu_support import NeighborSlave

from components.mission import ground_station as gs
from components.core import time_utils


class GroundStation(NeighborSlave):
    description = ("Ground station at UIUC (40.1020 N, 88.2272 W): elevation, azimuth, range and visibility of "
                   "the spacecraft, and the ground's final de-orbit confirmation during contacts")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("epoch", time_utils.DEFAULT_EPOCH, None,
                       "Scenario epoch (simulation time 0), ISO 8601 UTC 'YYYY-MM-DDThh:mm:ss[.fff]Z'", str)
        self.parameter("latitude", gs.UIUC_LATITUDE, "rad", "Station geodetic latitude (WGS-84); default 40.1020 deg N")
        self.parameter("longitude", gs.UIUC_LONGITUDE, "rad", "Station east longitude; default -88.2272 deg (W)")
        self.parameter("altitude", gs.UIUC_HEIGHT, "m", "Station height above the WGS-84 ellipsoid, in [-500, 10000]")
        self.parameter("elevation_mask", 0.0, "rad",
                       "Minimum elevation for contact, in [-pi/2, pi/2); default 0: the horizon, as the thesis' "
                       "FreeFlyer station without a mask")
        self.parameter("confirm_after", 0.0, "s",
                       "Operators confirm the de-orbit at contacts from this time on (ground_command)")
        self.parameter("approach_margin", gs.APPROACH_MARGIN, "rad",
                       "near_contact is true above elevation_mask - approach_margin, in [0, pi]; default 20 deg "
                       "(a 300-420 km orbit needs at least 448 s from there to the mask)")
        position = self.input_array("r_BN_N", [gs.geodesy.WGS84_A + 420e3, 0.0, 0.0], "m",
                                    "Spacecraft position relative to Earth's centre in N")
        look = lambda: self.model.look(self.vector("r_BN_N", 3))  # noqa: E731
        self.output("visible", lambda: look()[0] >= self.model.elevation_mask, None,
                    "Spacecraft in contact: elevation >= elevation_mask", bool, depends_on=position)
        self.output("elevation", lambda: look()[0], "rad", "Elevation of the spacecraft above the station's "
                    "horizon (ellipsoid normal)", depends_on=position)
        self.output("azimuth", lambda: look()[1], "rad", "Azimuth of the spacecraft from north toward east, "
                    "in [0, 2 pi)", depends_on=position)
        self.output("range", lambda: look()[2], "m", "Distance from the station to the spacecraft", depends_on=position)
        self.output("near_contact", lambda: self.model.near_contact(self.vector("r_BN_N", 3)), None,
                    "A contact may begin soon: elevation > elevation_mask - approach_margin", bool, depends_on=position)
        self.output("ground_command", lambda: self.model.ground_command(self.vector("r_BN_N", 3)), None,
                    "Ground's final de-orbit confirmation: visible and time >= confirm_after", bool,
                    depends_on=position)

    def build_model(self):
        v = self.values
        return gs.GroundStation(v["latitude"], v["longitude"], v["altitude"], v["elevation_mask"],
                                v["confirm_after"], v["epoch"], self.start_time, v["approach_margin"])

    def do_step(self, current_time, step_size):
        self.model.advance_to(current_time + step_size)
        return True
