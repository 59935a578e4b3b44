"""NEIGHBOR's on-board data storage and UHF downlink (the NEIGHBOR thesis, section 3.6, Table 7,
Figure 47, Appendix I).

Capacity: the STM32L432KC's "256 kB" flash, taken as 256000 bytes (k = 1000) because
Appendix I, which produced Figure 47, declares `DataStorageAvailable = 256e+3` bytes and plots
MB as bytes/1e6. (The part's flash is physically 256 KiB = 262144 bytes and also holds the
flight software, so 256000 is the figure the thesis analysed, not a measured free space.)

Recording rate: while `data_recording` is on, data accumulate at the Table 7 rate
(`TABLE7`, `table7_rate()`):
    1 s cadence:  attitude pitch/roll/yaw and their rates 6 x 4 B, GPS time 4 B  -> 28 B/s
    10 s cadence: GPS altitude, latitude, longitude 3 x 4 B                    -> 1.2 B/s
    60 s cadence: ADCS voltage and current 2 x 4 B, tank pressure 4 B, valve status 1 B,
                  thermocouples 48 B, battery voltage 4 B = 65 B                -> 1.0833 B/s
    total 1817 B per minute = 30.2833 B/s (the text rounds it: "30 bytes per second").
The two "Once" rows (thruster start and burn duration, 8 B per maneuver) are events, not a
rate, and are not included. Appendix I uses 29.503 B/s, 0.780 B/s (2.6 %) less; that value
does not follow from Table 7 as printed. It is within 0.02 B/s of Table 7 without the 48 B
thermocouple row (29.483 B/s), which may be the version it came from; this is a guess. Appendix
I also subtracts the 8 once-per-maneuver bytes from a display variable (`Data_Storage -= 8`,
in MB) rather than from the stored bytes. We use the Table 7 rate by default (a parameter).

Downlink: 9600 baud = 1200 B/s (8 bits per byte, as in Appendix I) while both
`downlink_enable` and `ground_contact` are on.

Integration: over a step the switches are held, so the net rate r = recording - downlink is
constant and the stored bytes are exact at any step size: the instant the store fills (r > 0)
or empties (r < 0) is found inside the step. Full: what does not fit is lost (counted in
`bytes_lost`, and `overflow` latches true); the downlink keeps sending at its full rate.
Empty while recording and downlinking: new data stream straight out (downlinked at the
recording rate). All byte counts are Real (rates are fractional bytes per second).
"""
import math

CAPACITY = 256e3  # bytes (k = 1000, as Appendix I)
BAUD = 9600.0
DOWNLINK_RATE = BAUD / 8.0  # 1200 B/s
APPENDIX_I_RATE = 29.503  # B/s, Appendix I's Bus_data

# Table 7: (component, data field, bytes, storage cadence in s or None for "Once")
TABLE7 = (
    ("Horizon/Sun Sensor", "Attitude Pitch (deg)", 4, 1.0),
    ("Horizon/Sun Sensor", "Attitude Roll (deg)", 4, 1.0),
    ("Horizon/Sun Sensor", "Attitude Yaw (deg)", 4, 1.0),
    ("Gyroscope", "Attitude Pitch Rate (deg/s)", 4, 1.0),
    ("Gyroscope", "Attitude Roll Rate (deg/s)", 4, 1.0),
    ("Gyroscope", "Attitude Yaw Rate (deg/s)", 4, 1.0),
    ("GPS", "Altitude (km)", 4, 10.0),
    ("GPS", "Latitude (deg)", 4, 10.0),
    ("GPS", "Longitude (deg)", 4, 10.0),
    ("GPS", "Time (unix time)", 4, 1.0),
    ("ADCS", "ADCS Voltage (V)", 4, 60.0),
    ("ADCS", "ADCS Current (A)", 4, 60.0),
    ("Propulsion Module", "Thruster Start (unix time)", 4, None),
    ("Propulsion Module", "Burn Duration (unix time)", 4, None),
    ("Propulsion Module", "Tank Pressure (Pa)", 4, 60.0),
    ("Propulsion Module", "Valve Status", 1, 60.0),
    ("Thermocouples", "Temperatures (K)", 48, 60.0),
    ("Battery", "Battery Voltage (V)", 4, 60.0),
)


def table7_rate(rows=TABLE7):
    """Average recording rate (B/s) of the periodic rows: sum of size / cadence."""
    return sum(size / cadence for _, _, size, cadence in rows if cadence is not None)


def table7_once_bytes(rows=TABLE7):
    """Bytes recorded once per maneuver (the 'Once' rows): 8."""
    return sum(size for _, _, size, cadence in rows if cadence is None)


RECORDING_RATE = table7_rate()  # 30.28333... B/s


def _number(name, value, unit, low=0.0, high=math.inf, positive=False):
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    ok = not isinstance(value, bool) and math.isfinite(v) and low <= v <= high and (v > 0.0 or not positive)
    if not ok:
        bound = f"> {low}" if positive else f"in [{low}, {high}]"
        raise ValueError(f"{name} = {value!r} must be a finite number {bound} {unit}")
    return v


class DataStorage:
    """Flash store filled by recording and emptied by the UHF downlink.

    DataStorage(capacity=256000 B, recording_rate=30.2833 B/s, downlink_rate=1200 B/s,
    initial_storage_used=0 B)."""

    def __init__(self, capacity=CAPACITY, recording_rate=RECORDING_RATE, downlink_rate=DOWNLINK_RATE,
                 initial_storage_used=0.0):
        self.capacity = _number("capacity", capacity, "byte", positive=True)
        self.recording_rate = _number("recording_rate", recording_rate, "byte/s")
        self.downlink_rate = _number("downlink_rate", downlink_rate, "byte/s")
        self.storage_used = _number("initial_storage_used", initial_storage_used, "byte", 0.0, self.capacity)
        self.bytes_lost = 0.0
        self.downlinked = 0.0
        self.overflow = False

    @property
    def storage_free(self):
        return self.capacity - self.storage_used

    def downlink_active(self, downlink_enable, ground_contact):
        return bool(downlink_enable) and bool(ground_contact)

    def step(self, data_recording, downlink_enable, ground_contact, dt):
        """Advance by dt seconds with the three switches held."""
        dt = _number("step size", dt, "s")
        rec = self.recording_rate if data_recording else 0.0
        down = self.downlink_rate if self.downlink_active(downlink_enable, ground_contact) else 0.0
        net = rec - down
        s0 = self.storage_used
        if net > 0.0:
            t_full = (self.capacity - s0) / net
            if dt <= t_full:
                self.storage_used = s0 + net * dt
            else:
                self.storage_used = self.capacity
                lost = net * (dt - t_full)
                self.bytes_lost += lost
                if lost > 0.0:
                    self.overflow = True
            self.downlinked += down * dt
        elif net < 0.0:
            t_empty = s0 / -net
            if dt <= t_empty:
                self.storage_used = max(0.0, s0 + net * dt)
                self.downlinked += down * dt
            else:  # emptied inside the step; then new data stream straight out
                self.storage_used = 0.0
                self.downlinked += down * t_empty + rec * (dt - t_empty)
        else:  # recording exactly matched by the downlink (or both off)
            self.downlinked += down * dt

    def get_state(self):
        return {"storage_used": self.storage_used, "bytes_lost": self.bytes_lost,
                "downlinked": self.downlinked, "overflow": self.overflow}

    def set_state(self, state):
        self.storage_used = float(state["storage_used"])
        self.bytes_lost = float(state["bytes_lost"])
        self.downlinked = float(state["downlinked"])
        self.overflow = bool(state["overflow"])
