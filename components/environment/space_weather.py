"""Space-weather indices for the atmosphere models: solar flux F10.7 and geomagnetic Kp/Ap.

Two sources with the same interface:

- `SpaceWeather.from_file(path=None)`: a CelesTrak/CSSI "SpaceWx" file, fixed-width format
  version 1.2 (https://celestrak.org/SpaceData/SpaceWx-format.php; the format line is in the
  file header: FORMAT(I4,I3,I3,I5,I3,8I3,I4,8I4,I4,F4.1,I2,I4,F6.1,I2,5F6.1)), with its three
  sections OBSERVED, DAILY_PREDICTED and MONTHLY_PREDICTED. `path=None` reads the bundled copy
  components/environment/data/SW-All_CSSI_2026-08-22_from2000.txt (see components/environment/data/README.md: the
  CelesTrak file of 2026-08-22, observed section trimmed to 2000-01-01 on, header and both
  prediction sections unchanged).
- `ConstantSpaceWeather(f107, f107a, ap)`: the same indices on every day.

Daily table. Every entry is valid from 0h UTC of its date until the next entry's date (so a
monthly prediction holds for its month, and the gap between the daily and monthly
predictions holds the last daily prediction). The monthly predictions carry no Kp/Ap: the
geomagnetic indices of the last entry that has them are held. After the last entry (2041-10-01
in the bundled file) the last entry is held indefinitely, FreeFlyer's behaviour (thesis
section 2.5); `past_end(jd)` says whether a date is in that held region. A date before the
first entry is an error naming the date and the coverage. Quantities that need earlier days
(F10.7 of the previous day, ap up to 57 h earlier) use the first entry on the first day.

F10.7 comes in two kinds: "observed" (the flux measured at 1 AU distance of the day, what
NRLMSIS and Jacchia's models were fitted to) and "adjusted" (scaled to 1 AU). Methods take
`kind="observed"` or `"adjusted"`. Solar flux units (sfu, 1e-22 W m^-2 Hz^-1) throughout.

Arrays for numba kernels (`kernel_arrays()`): (jd0, daily, ap3h) with
  jd0   float: Julian date of 0h UTC of the first day,
  daily float64[ndays, NCOL]: one row per day from the first date (columns COL_*),
  ap3h  float64[8 ndays]: the 3-hourly ap, index 8 * day + floor(hour / 3).
`day_index(jd, jd0, n)` (njit) gives the row, clamped to the last row (held values) and -1
before the first day.
"""
import datetime as _dt
import math
import os

import numpy as np

from ..core.jit import njit

DATA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
BUNDLED_FILE = os.path.join(DATA_DIR, "SW-All_CSSI_2026-08-22_from2000.txt")
PACKAGE_DATA = ("data/SW-All_CSSI_2026-08-22_from2000.txt",)  # what an FMU that imports this bundles

# daily-table columns
COL_F107_OBS = 0          # observed F10.7 of the day
COL_F107_OBS_PREV = 1     # observed F10.7 of the previous day
COL_F107_OBS_CTR81 = 2    # 81-day centred mean of observed F10.7
COL_F107_ADJ = 3
COL_F107_ADJ_PREV = 4
COL_F107_ADJ_CTR81 = 5
COL_AP_DAILY = 6          # daily Ap
COL_KP = 7                # 7..14: the eight 3-hourly Kp (as real numbers, e.g. 1.7 for "17")
NCOL = 15

KINDS = ("observed", "adjusted")
_F107_COLS = {"observed": (COL_F107_OBS, COL_F107_OBS_PREV, COL_F107_OBS_CTR81),
              "adjusted": (COL_F107_ADJ, COL_F107_ADJ_PREV, COL_F107_ADJ_CTR81)}
_JD_UNIX_EPOCH = 2440587.5
F107_RANGE = (50.0, 400.0)  # sfu: NRLMSIS/Jacchia are fitted within about 60-300 sfu
AP_RANGE = (0.0, 400.0)     # the Ap scale ends at 400


def _jd_of_date(year, month, day):
    d = _dt.date(year, month, day)
    return _JD_UNIX_EPOCH + (d - _dt.date(1970, 1, 1)).days


def _date_of_jd(jd):
    return (_dt.datetime(1970, 1, 1) + _dt.timedelta(days=jd - _JD_UNIX_EPOCH)).isoformat(timespec="seconds") + "Z"


@njit(cache=True)
def day_index(jd, jd0, n):
    """Row of the daily table for Julian date jd: -1 before the first day, held at n - 1."""
    d = math.floor(jd - jd0)
    if d < 0.0:
        return -1
    if d > n - 1:
        return n - 1
    return int(d)


@njit(cache=True)
def ap_3h_at(jd, jd0, ap3h, hours_before):
    """3-hourly ap of the interval containing jd - hours_before (clamped to the table)."""
    k = math.floor((jd - jd0) * 8.0 - hours_before / 3.0)
    n = ap3h.shape[0]
    if k < 0.0:
        return ap3h[0]
    if k > n - 1:
        return ap3h[n - 1]
    return ap3h[int(k)]


class _IndexSource:
    """Python access to the daily table (shared by file and constant space weather)."""

    jd0 = 0.0
    daily = None
    ap3h = None
    description = ""

    # ---- coverage ------------------------------------------------------------------------
    @property
    def first_jd(self):
        return self.jd0

    @property
    def last_jd(self):
        """Julian date of 0h of the last entry's day."""
        return self.jd0 + self.daily.shape[0] - 1

    def _row(self, jd_utc):
        jd = float(jd_utc)
        if not math.isfinite(jd):
            raise ValueError(f"Julian date {jd_utc!r} must be finite")
        i = day_index(jd, self.jd0, self.daily.shape[0])
        if i < 0:
            raise ValueError(f"date {_date_of_jd(jd)} (JD {jd}) is before the first entry of the space-weather "
                             f"data {self.description} (covers {self.coverage()})")
        return self.daily[i]

    def coverage(self):
        return f"{_date_of_jd(self.jd0)} to {_date_of_jd(self.last_jd + 1.0)}, last entry held after that"

    def past_end(self, jd_utc):
        """True when jd_utc is after the last entry's day, where the last entry is held."""
        return float(jd_utc) >= self.last_jd + 1.0

    # ---- indices -------------------------------------------------------------------------
    @staticmethod
    def _cols(kind):
        if kind not in _F107_COLS:
            raise ValueError(f"F10.7 kind {kind!r} must be one of {KINDS}")
        return _F107_COLS[kind]

    def f107(self, jd_utc, kind="observed"):
        """F10.7 (sfu) of the day of jd_utc."""
        return float(self._row(jd_utc)[self._cols(kind)[0]])

    def f107_previous_day(self, jd_utc, kind="observed"):
        """F10.7 (sfu) of the day before the day of jd_utc (what NRLMSIS takes); after the last
        entry, the last entry's F10.7 (held)."""
        row = self._row(jd_utc)
        return float(row[self._cols(kind)[0 if self.past_end(jd_utc) else 1]])

    def f107a(self, jd_utc, kind="observed"):
        """81-day centred mean of F10.7 (sfu) at the day of jd_utc."""
        return float(self._row(jd_utc)[self._cols(kind)[2]])

    def ap_daily(self, jd_utc):
        return float(self._row(jd_utc)[COL_AP_DAILY])

    def kp_3h(self, jd_utc):
        """3-hourly Kp (0..9) of the interval containing jd_utc."""
        row = self._row(jd_utc)
        frac = float(jd_utc) - math.floor(float(jd_utc) - self.jd0) - self.jd0
        return float(row[COL_KP + min(int(frac * 8.0), 7)])

    def ap_3h(self, jd_utc, hours_before=0.0):
        """3-hourly ap of the interval containing jd_utc - hours_before."""
        self._row(jd_utc)
        return float(ap_3h_at(float(jd_utc), self.jd0, self.ap3h, float(hours_before)))

    def msis_ap(self, jd_utc):
        """The 7 NRLMSIS ap inputs: daily Ap; 3-h ap now, 3, 6 and 9 h before; means of the
        eight 3-h ap 12-33 h and 36-57 h before."""
        jd = float(jd_utc)
        a = [self.ap_daily(jd)] + [self.ap_3h(jd, h) for h in (0.0, 3.0, 6.0, 9.0)]
        a.append(sum(self.ap_3h(jd, 12.0 + 3.0 * k) for k in range(8)) / 8.0)
        a.append(sum(self.ap_3h(jd, 36.0 + 3.0 * k) for k in range(8)) / 8.0)
        return a

    def kernel_arrays(self):
        """(jd0, daily float64[ndays, NCOL], ap3h float64[8 ndays]) for numba kernels."""
        return (float(self.jd0), self.daily, self.ap3h)


class ConstantSpaceWeather(_IndexSource):
    """The same F10.7 (of every day, hence also of the previous day, both kinds), 81-day mean
    F10.7 and Ap (daily and every 3-hourly ap; Kp from the Ap-to-Kp table) on every date."""

    def __init__(self, f107, f107a, ap):
        for name, value, (lo, hi), unit in (("f107", f107, F107_RANGE, " sfu"), ("f107a", f107a, F107_RANGE, " sfu"),
                                            ("ap", ap, AP_RANGE, "")):
            v = float(value)
            if not (lo <= v <= hi):
                raise ValueError(f"{name} = {value!r} must be in [{lo:g}, {hi:g}]{unit}")
        self.f107_value, self.f107a_value, self.ap_value = float(f107), float(f107a), float(ap)
        row = np.empty(NCOL)
        row[[COL_F107_OBS, COL_F107_OBS_PREV, COL_F107_ADJ, COL_F107_ADJ_PREV]] = self.f107_value
        row[[COL_F107_OBS_CTR81, COL_F107_ADJ_CTR81]] = self.f107a_value
        row[COL_AP_DAILY] = self.ap_value
        row[COL_KP:COL_KP + 8] = kp_from_ap(self.ap_value)
        self.daily = row.reshape(1, NCOL)
        self.ap3h = np.full(8, self.ap_value)
        self.jd0 = -1.0e9  # every date of interest is after the (only) entry, which is held
        self.description = f"(constant F10.7 = {f107:g}, F10.7a = {f107a:g}, Ap = {ap:g})"

    def coverage(self):
        return "all dates (constant)"

    def past_end(self, jd_utc):
        return False


# Kp <-> ap conversion table (Bartels; the 28 Kp steps 0o, 0+, 1-, ..., 9o).
_KP_STEPS = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25,
                      26, 27]) / 3.0
_AP_STEPS = np.array([0, 2, 3, 4, 5, 6, 7, 9, 12, 15, 18, 22, 27, 32, 39, 48, 56, 67, 80, 94, 111, 132, 154, 179, 207,
                      236, 300, 400], float)


def kp_from_ap(ap):
    """Kp for an ap value, interpolated linearly in the Bartels ap/Kp table."""
    return float(np.interp(float(ap), _AP_STEPS, _KP_STEPS))


# ---- CSSI file ---------------------------------------------------------------------------------
_SECTIONS = ("OBSERVED", "DAILY_PREDICTED", "MONTHLY_PREDICTED")


def _field(line, a, b):
    s = line[a:b].strip()
    return float(s) if s else math.nan


class SpaceWeather(_IndexSource):
    """Indices from a CSSI space-weather file (see the module docstring)."""

    def __init__(self, dates, rows, path):
        """`dates`: sorted Julian dates (0h UTC) of the entries; `rows`: float array [n, 30]
        of the fields (NaN where blank), columns as stored by `from_file`."""
        self.path = path
        self.description = f"file {path!r}"
        self.jd0 = float(dates[0])  # 0h UTC of the first entry's date
        ndays = int(round(dates[-1] - dates[0])) + 1
        # forward-fill: every entry is valid until the next entry's date
        idx = np.searchsorted(np.asarray(dates), self.jd0 + np.arange(ndays) + 0.25, side="right") - 1
        raw = rows[idx].copy()
        for c in range(raw.shape[1]):  # blank fields (monthly Kp/Ap) hold the last value given
            col = raw[:, c]
            good = ~np.isnan(col)
            if not good.any():
                continue
            pos = np.where(good, np.arange(len(col)), 0)
            np.maximum.accumulate(pos, out=pos)
            filled = col[pos]
            filled[:np.argmax(good)] = col[np.argmax(good)]
            raw[:, c] = filled
        daily = np.empty((ndays, NCOL))
        daily[:, COL_F107_OBS] = raw[:, 27]
        daily[:, COL_F107_OBS_CTR81] = raw[:, 28]
        daily[:, COL_F107_ADJ] = raw[:, 24]
        daily[:, COL_F107_ADJ_CTR81] = raw[:, 25]
        daily[:, COL_F107_OBS_PREV] = np.concatenate([raw[:1, 27], raw[:-1, 27]])
        daily[:, COL_F107_ADJ_PREV] = np.concatenate([raw[:1, 24], raw[:-1, 24]])
        daily[:, COL_AP_DAILY] = raw[:, 21]
        daily[:, COL_KP:COL_KP + 8] = raw[:, 4:12] / 10.0
        self.daily = daily
        self.ap3h = np.ascontiguousarray(raw[:, 13:21]).reshape(-1)
        if np.isnan(self.daily).any() or np.isnan(self.ap3h).any():
            raise ValueError(f"space-weather file {path!r}: some indices are blank in every entry")

    @classmethod
    def from_file(cls, path=None):
        path = BUNDLED_FILE if path in (None, "") else os.fspath(path)
        try:
            with open(path, encoding="ascii") as f:
                lines = f.read().splitlines()
        except (OSError, UnicodeDecodeError) as exc:
            raise ValueError(f"space-weather file {path!r} cannot be read: {exc}") from None

        def fail(n, msg):
            raise ValueError(f"space-weather file {path!r}, line {n}: {msg}")

        if not lines or lines[0].split() != ["DATATYPE", "CssiSpaceWeather"]:
            fail(1, "expected 'DATATYPE CssiSpaceWeather' (CSSI SpaceWx format)")
        version = next((ln.split()[1] for ln in lines[:5] if ln.startswith("VERSION") and len(ln.split()) > 1), None)
        if version != "1.2":
            fail(2, f"format version {version!r} is not supported (expected VERSION 1.2)")
        dates, rows, counts, declared = [], [], {}, {}
        section, prev_jd = None, -math.inf
        for n, line in enumerate(lines, 1):
            if line.startswith("NUM_") and "_POINTS" in line:
                key = line.split()[0][4:-7]
                try:
                    declared[key] = int(line.split()[1])
                except (IndexError, ValueError):
                    fail(n, f"bad point count {line!r}")
            elif line.startswith("BEGIN "):
                section = line.split()[1]
                if section not in _SECTIONS:
                    fail(n, f"unknown section {section!r}")
                counts[section] = 0
            elif line.startswith("END "):
                if line.split()[1] != section:
                    fail(n, f"{line!r} does not close section {section!r}")
                section = None
            elif section is not None:
                try:
                    year, month, day = int(line[0:4]), int(line[4:7]), int(line[7:10])
                    jd = _jd_of_date(year, month, day)
                    raw = [_field(line, 10, 15), _field(line, 15, 18), math.nan, math.nan]
                    raw += [_field(line, 18 + 3 * k, 21 + 3 * k) for k in range(8)]
                    raw += [_field(line, 42, 46)]
                    raw += [_field(line, 46 + 4 * k, 50 + 4 * k) for k in range(8)]
                    raw += [_field(line, 78, 82), _field(line, 82, 86), _field(line, 86, 88), _field(line, 88, 92)]
                    raw += [_field(line, 92, 98), _field(line, 98, 100)]
                    raw += [_field(line, 100 + 6 * k, 106 + 6 * k) for k in range(5)]
                except ValueError as exc:
                    fail(n, f"entry does not parse ({exc}): {line!r}")
                # raw: [0 BSRN, 1 ND, 2-3 unused, 4-11 Kp*10, 12 Sum, 13-20 ap, 21 Avg (daily Ap), 22 Cp,
                #       23 C9, 24 ISN, 25 F10.7adj, 26 Q, 27 Ctr81adj, 28 Lst81adj, 29 F10.7obs, 30 Ctr81obs,
                #       31 Lst81obs]
                if not all(0.0 < raw[k] < 1000.0 for k in (25, 27, 29, 30)):  # also false for NaN (blank)
                    fail(n, f"F10.7 fields missing or out of range: {line!r}")
                if jd <= prev_jd:
                    fail(n, f"date {year:04d}-{month:02d}-{day:02d} is not after the previous entry")
                prev_jd = jd
                # stored as the constructor expects: 4..11 Kp*10, 13..20 ap, 21 Ap, 24 adj, 25 adj ctr81,
                # 27 obs, 28 obs ctr81
                row = raw[:24] + [raw[25], raw[27], math.nan, raw[29], raw[30], math.nan]
                dates.append(jd)
                rows.append(row)
                counts[section] += 1
        if section is not None:
            fail(len(lines), f"section {section} is not closed")
        for key, num in declared.items():
            if counts.get(key) != num:
                fail(len(lines), f"NUM_{key}_POINTS says {num} but the section has {counts.get(key, 0)} entries")
        if "OBSERVED" not in counts or not dates:
            fail(len(lines), "no OBSERVED section with entries")
        return cls(np.array(dates), np.array(rows), path)


# F10.7 fields of a CSSI line (format 1.2): adjusted, its centred and last 81-day means, then the
# same three observed
F107_FIELDS = ((92, 98), (100, 106), (106, 112), (112, 118), (118, 124), (124, 130))


def scaled_copy(factor, dest, source=None):
    """Write a copy of the CSSI file `source` (default: the bundled one) to `dest` with every
    F10.7 value (observed and adjusted, daily and 81-day means) multiplied by `factor` (capped at
    the format's 999.9): a solar cycle `factor` times as strong, for dispersing solar activity.
    Geomagnetic indices unchanged."""
    factor = float(factor)
    if not (math.isfinite(factor) and 0.1 <= factor <= 10.0):
        raise ValueError(f"F10.7 scale factor {factor!r} must be in [0.1, 10]")
    source = BUNDLED_FILE if source in (None, "") else os.fspath(source)
    with open(source, encoding="ascii") as f:
        lines = f.read().splitlines()
    out, section = [], None
    for line in lines:
        if line.startswith("BEGIN "):
            section = line.split()[1]
        elif line.startswith("END "):
            section = None
        elif section is not None and len(line) >= 130:
            chars = list(line)
            for a, b in F107_FIELDS:
                text = line[a:b].strip()
                if text:
                    # the format holds 999.9 at most (a flare day of 924 sfu scaled up would not fit)
                    chars[a:b] = f"{min(float(text) * factor, 999.9):{b - a}.1f}"
            line = "".join(chars)
        out.append(line)
    with open(dest, "w", encoding="ascii") as f:
        f.write("\n".join(out) + "\n")
    return dest


# ap -> Kp x 10 (the standard 28-step conversion, Kp 0o..9o), for writing held geomagnetic levels
AP_TO_KP10 = {0: 0, 2: 3, 3: 7, 4: 10, 5: 13, 6: 17, 7: 20, 9: 23, 12: 27, 15: 30, 18: 33, 22: 37, 27: 40, 32: 43,
              39: 47, 48: 50, 56: 53, 67: 57, 80: 60, 94: 63, 111: 67, 132: 70, 154: 73, 179: 77, 207: 80, 236: 83,
              300: 87, 400: 90}


def held_copy(dest, levels, source=None):
    """Write a CSSI file made of the history of `source` (default: the bundled file) before the
    first of `levels`, then one entry per level: `levels` is [(date 'YYYY-MM-DD', F10.7 sfu, ap),
    ...] in date order, F10.7 used for the daily and 81-day means (observed and adjusted) and ap
    for every 3 h (one of AP_TO_KP10's values). An entry holds until the next one, and the last
    is held after the file's end (FreeFlyer's behaviour). Stands in for an older file: its
    predictions as levels, then the last entry it held. Prediction sections are left empty."""
    if not levels:
        raise ValueError("held_copy needs at least one (date, F10.7, ap) level")
    steps, prev = [], -math.inf
    for date, f107, ap in levels:
        year, month, day = (int(x) for x in str(date).split("-"))
        jd = _jd_of_date(year, month, day)
        f107 = float(f107)
        if jd <= prev:
            raise ValueError(f"space-weather levels: {date} is not after the previous level's date")
        if not (math.isfinite(f107) and 50.0 <= f107 <= 400.0):
            raise ValueError(f"space-weather level at {date}: F10.7 {f107!r} sfu must be in [50, 400]")
        if ap not in AP_TO_KP10:
            raise ValueError(f"space-weather level at {date}: ap {ap!r} must be one of {sorted(AP_TO_KP10)}")
        steps.append((year, month, day, f107, ap))
        prev = jd
    jd_first = _jd_of_date(*steps[0][:3])
    source = BUNDLED_FILE if source in (None, "") else os.fspath(source)
    with open(source, encoding="ascii") as f:
        lines = f.read().splitlines()
    head, observed, section = [], [], None
    for line in lines:
        if line.startswith("BEGIN "):
            section = line.split()[1]
        elif line.startswith("END "):
            section = None
        elif section == "OBSERVED":
            if _jd_of_date(int(line[0:4]), int(line[4:7]), int(line[7:10])) < jd_first:
                observed.append(line)
        elif section is None and not line.startswith("NUM_") and not observed:
            head.append(line)
    if not observed:
        raise ValueError(f"space-weather file {source!r} has no observed entry before {levels[0][0]}")
    last = observed[-1]
    rows = []
    for year, month, day, f107, ap in steps:
        kp10 = AP_TO_KP10[ap]
        rows.append(f"{year:4d} {month:02d} {day:02d}" + last[10:18] + f"{kp10:3d}" * 8 + f"{8 * kp10:4d}"
                    + f"{ap:4d}" * 9 + last[82:92] + f"{f107:6.1f}" + last[98:100] + f"{f107:6.1f}" * 5)
    out = head + [f"NUM_OBSERVED_POINTS {len(observed) + len(rows)}", "BEGIN OBSERVED", *observed, *rows,
                  "END OBSERVED", "NUM_DAILY_PREDICTED_POINTS 0", "BEGIN DAILY_PREDICTED", "END DAILY_PREDICTED",
                  "NUM_MONTHLY_PREDICTED_POINTS 0", "BEGIN MONTHLY_PREDICTED", "END MONTHLY_PREDICTED"]
    with open(dest, "w", encoding="ascii") as f:
        f.write("\n".join(out) + "\n")
    return dest
