"""Scenario epoch and Julian dates.

Simulation time is seconds since the scenario epoch (docs/conventions.md). The epoch is an ISO 8601
UTC string, "YYYY-MM-DDThh:mm:ss[.fff]Z" (or "+00:00" instead of "Z"); `parse_epoch` accepts
nothing else (no local times, no other offsets, no date-only strings), so a typo cannot shift
the scenario silently.

Time scale: the Julian dates here are UTC Julian dates. The Sun model of `components.environment.sun` is the
low-precision algorithm (good to about 0.01 deg), which Vallado evaluates with T_UT1 for both the
mean longitude and the mean anomaly; we use UTC for UT1 (|UT1 - UTC| < 0.9 s) and ignore the
TT - UTC offset of 69.184 s, which moves the Sun by 0.0008 deg, well below the model's accuracy.
"""
import datetime as _dt
import math
import re

from .constants import DAY, DAYS_PER_CENTURY

J2000_JD = 2451545.0  # 2000-01-01 12:00 (taken as UTC here, see the module docstring)
DEFAULT_EPOCH = "2023-01-01T00:00:00Z"

_ISO_UTC = re.compile(r"(\d{4})-(\d{2})-(\d{2})T(\d{2}):(\d{2}):(\d{2})(\.\d{1,9})?(Z|\+00:00)")
_J2000 = _dt.datetime(2000, 1, 1, 12, 0, 0, tzinfo=_dt.timezone.utc)


def parse_epoch(text, name="epoch"):
    """UTC datetime of an ISO 8601 UTC string; ValueError naming `name` otherwise."""
    if not isinstance(text, str):
        raise ValueError(f"{name} = {text!r} must be an ISO 8601 UTC string like {DEFAULT_EPOCH!r}")
    m = _ISO_UTC.fullmatch(text.strip())
    if m is None:
        raise ValueError(f"{name} = {text!r} is not an ISO 8601 UTC date-time; expected "
                         f"'YYYY-MM-DDThh:mm:ss[.fff]Z', e.g. {DEFAULT_EPOCH!r}")
    year, month, day, hour, minute, second = (int(g) for g in m.groups()[:6])
    frac = m.group(7)
    micro = round(float(frac) * 1e6) if frac else 0
    if micro == 1_000_000:
        micro = 999_999
    try:
        return _dt.datetime(year, month, day, hour, minute, second, micro, tzinfo=_dt.timezone.utc)
    except ValueError as exc:  # e.g. month 13, Feb 30, second 60 (leap seconds are not supported)
        raise ValueError(f"{name} = {text!r} is not a valid UTC date-time ({exc})") from None


def seconds_since_j2000(epoch):
    """Seconds from J2000 (2000-01-01T12:00:00 UTC) to `epoch` (a datetime or an ISO string)."""
    if isinstance(epoch, str):
        epoch = parse_epoch(epoch)
    delta = epoch - _J2000
    return delta.days * DAY + delta.seconds + delta.microseconds * 1e-6


def julian_date(epoch, t=0.0):
    """UTC Julian date of epoch + t seconds."""
    return J2000_JD + (seconds_since_j2000(epoch) + float(t)) / DAY


def julian_centuries(epoch, t=0.0):
    """Julian centuries since J2000 of epoch + t seconds (UTC used for UT1/TDB, see above)."""
    return (seconds_since_j2000(epoch) + float(t)) / (DAY * DAYS_PER_CENTURY)


def check_time(t, name="t"):
    t = float(t)
    if not math.isfinite(t):
        raise ValueError(f"{name} = {t!r} must be a finite number of seconds")
    return t


class Clock:
    """Simulation time for models whose outputs are functions of time only (ephemerides,
    analytic orbits): `t` is the current time in s since the epoch, and it is their only
    state."""

    t = 0.0

    def advance_to(self, t):
        self.t = check_time(t, "time")

    def step(self, h):
        self.advance_to(self.t + h)

    def get_state(self):
        return {"t": self.t}

    def set_state(self, state):
        self.advance_to(state["t"])
