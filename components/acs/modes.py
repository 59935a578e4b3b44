"""ACS mode manager of the ACS mode specification: ten modes of a spinning spacecraft with three magnetic torque
coils, a momentum wheel on Y, deployable solar paddles on the +Z face and a star-tracking
optical system, driven by the specification's decision tables.

Modes: 0 Wait, 1 Detumble, 2 Spinup, 3 Reorient, 4 Deploy Wheel, 5 Acquire, 6 Deploy Paddles,
7 Orbit Day, 8 Orbit Night, 9 Ground Command.

Tables as data
--------------
Every column of every table of the specification is one `Rule` in `RULES`, in the specification's order: the
mode whose table holds it (= the mode it leads into), its 1-based column, the current modes it
applies from ("Control Mode" rows) and its conditions ("State Values" rows) by name, True/False
as printed (a blank is a don't-care and is left out). Condition names are the specification's rows
written as predicates:

- Booleans: `orbit_day`, `paddles_deployed`, `optical_tracking`, `reset`, `ground_command`;
- comparisons `<quantity> <op> <threshold>` with op one of > >= < <=. Quantities:
  `xz_momentum_error`, `momentum_error`, `|wheel_rate|`, `|sin_sun_elevation|`,
  `|sin_sun_azimuth|`, `body_rate`, `t_in_mode`; thresholds are parameter names
  (`PARAMETER_DEFAULTS`), the mode delays by the specification's abbreviations (WMD ... GCMD).

Every delay row of the specification ("t - t(entered X) >= D") names the mode X the column applies from,
so it is written `t_in_mode >= D` (checked when the tables are built). Times are compared with a
tolerance TIME_TOL = 1 ns, so that communication points accumulated in floating point
(100 steps of 0.1 s) reach a delay; `t_in_mode >= D` is true from t_in_mode >= D - 1 ns.
Sun errors are magnitudes: the specification compares "sine sun elevation/azimuth" with error bounds,
so the absolute values of the sines are compared (the sign says on which side the Sun is; a
sine cannot tell azimuth a from 180 deg - a, the specification's choice, see the module's README).
`|wheel_rate|`: the wheel may spin either way about Y.

Where the draft contradicts itself, a rule's `conditions` differ from what the specification prints; the
literal seed values are then in `seed_conditions` and the reason in `note` (amendments A1-A6,
listed in `AMENDMENTS`). Columns the specification does not print but its text requires are marked
`added=True`.

Evaluation semantics (`decide`)
-------------------------------
At each evaluation, with the current mode m, the time in mode and the inputs, every rule whose
from-modes contain m and whose conditions all hold "fires". Then, in this order:

1. a firing reset rule (Wait col 2, from any mode) -> Wait, re-entered (its timer restarts,
   also when already in Wait: a reset held true keeps restarting WMD);
2. a firing ground-command rule -> Ground Command, re-entered (each command received restarts
   GCMD; Wait accepts a command only once WMD elapsed, A6);
3. transitions out (firing rules whose target is not m): if all lead to the same mode, enter it;
   if they lead to different modes, the controller is uncertain -> Spinup;
4. holds (firing rules whose target is m): stay, the timer keeps running;
5. no rule fires: the controller is uncertain -> Spinup.

"Uncertain" is exactly cases 3-with-conflict and 5; the decision falls back to Spinup, the
specification's safe mode, and `uncertain` is set until the next decision. A fallback while already in
Spinup stays in Spinup without restarting its timer (so SMD can elapse); from another mode it
enters Spinup. Startup is the pseudo-mode STARTUP, whose only rule (Wait col 1) enters Wait at
the start time.

Time: `step(t, h, inputs)` evaluates the decision at the communication point t with the inputs
present at t and the time in mode t - t_entered; a transition enters its mode at t
(t_entered = t) and the mode holds over [t, t + h]. After the step the model's time is t + h,
so `time_in_mode` reads (t + h) - t_entered. A delay condition `t_in_mode >= D` therefore fires
at the first communication point at least D after the mode was entered, never before.

Actuator permissions per mode (`PERMISSIONS`) follow the specification's mode descriptions.
"""
import math
import re
from dataclasses import dataclass, field
from enum import IntEnum

from ..core.checks import finite_parameters


class AcsMode(IntEnum):
    """The ten modes of the specification's draft, in its numbering (the FMU output `mode`)."""
    WAIT = 0
    DETUMBLE = 1
    SPINUP = 2
    REORIENT = 3
    DEPLOY_WHEEL = 4
    ACQUIRE = 5
    DEPLOY_PADDLES = 6
    ORBIT_DAY = 7
    ORBIT_NIGHT = 8
    GROUND_COMMAND = 9


# The decision tables below read best with bare names: one per mode, in value order.
(WAIT, DETUMBLE, SPINUP, REORIENT, DEPLOY_WHEEL, ACQUIRE, DEPLOY_PADDLES, ORBIT_DAY, ORBIT_NIGHT,
 GROUND_COMMAND) = AcsMode
STARTUP = -1  # pseudo-mode before the first decision ("Control Mode: Startup")
MODE_NAMES = ("Wait", "Detumble", "Spinup", "Reorient", "Deploy Wheel", "Acquire", "Deploy Paddles",
              "Orbit Day", "Orbit Night", "Ground Command")
MODES = tuple(AcsMode)
ANY = MODES
MODE_TABLE = ", ".join(f"{i} {n}" for i, n in enumerate(MODE_NAMES))
SAFE_MODE = SPINUP
TIME_TOL = 1e-9  # s

DELAYS = ("WMD", "DMD", "SMD", "RMD", "DWMD", "AMD", "DPMD", "ODMD", "GCMD")
# The mode each delay is measured in ("t - t(entered X)").
DELAY_MODE = {"WMD": WAIT, "DMD": DETUMBLE, "SMD": SPINUP, "RMD": REORIENT, "DWMD": DEPLOY_WHEEL,
              "AMD": ACQUIRE, "DPMD": DEPLOY_PADDLES, "ODMD": ORBIT_DAY, "GCMD": GROUND_COMMAND}

# Defaults. The delays are the specification's. The thresholds are ours, for a 6U-class spacecraft of
# about 0.1 kg.m2 per axis (the NEIGHBOR host's order of magnitude) spun at the specification's 5 deg/s
# about Y: spin momentum 0.1 * 5 deg/s = 8.7e-3 N.m.s.
PARAMETER_DEFAULTS = {
    # detumbled when the X-Z momentum is below 1e-3 N.m.s (0.57 deg/s transverse rate at 0.1 kg.m2)
    "xz_momentum_error_threshold": 1.0e-3,
    # spun up when the momentum error is below 1e-3 N.m.s, 11 % of the 8.7e-3 N.m.s spin momentum
    "spinup_momentum_error": 1.0e-3,
    # coarse Sun errors: sin 10 deg (Acquire's "+/-10 deg", printed "+/-100" in the draft)
    "coarse_elevation_error": math.sin(math.radians(10.0)),
    "coarse_azimuth_error": math.sin(math.radians(10.0)),
    # fine Sun errors: sin 2 deg (operations pointing, 5x tighter than coarse)
    "fine_elevation_error": math.sin(math.radians(2.0)),
    "fine_azimuth_error": math.sin(math.radians(2.0)),
    # 1 deg/s: star trackers of this class lose track at a few deg/s; 10x the ~0.07 deg/s of an
    # inertially held spacecraft in LEO
    "max_tumble_rate": math.radians(1.0),
    # 400 rad/s (3800 rpm): a 2.2e-5 kg.m2 rotor then holds the 8.7e-3 N.m.s of the 5 deg/s spin
    # (Deploy Wheel transfers the Y momentum to the wheel); within small wheels' 0-6000 rpm
    "nominal_wheel_rate": 400.0,
    "WMD": 10.0, "DMD": 100.0, "SMD": 100.0, "RMD": 6000.0, "DWMD": 180.0,
    "AMD": 10.0, "DPMD": 120.0, "ODMD": 10.0, "GCMD": 10.0,
}
UNIT_PARAMETERS = ("coarse_elevation_error", "coarse_azimuth_error", "fine_elevation_error", "fine_azimuth_error")

INPUT_DEFAULTS = {
    "xz_momentum_error": 0.0, "momentum_error": 0.0, "wheel_rate": 0.0,
    "sin_sun_elevation": 0.0, "sin_sun_azimuth": 0.0, "body_rate": 0.0,
    "orbit_day": False, "paddles_deployed": False, "optical_tracking": False,
    "ground_command": False, "reset": False,
}
BOOLEAN_INPUTS = ("orbit_day", "paddles_deployed", "optical_tracking", "ground_command", "reset")
QUANTITIES = {
    "xz_momentum_error": lambda i, tm: i["xz_momentum_error"],
    "momentum_error": lambda i, tm: i["momentum_error"],
    "|wheel_rate|": lambda i, tm: abs(i["wheel_rate"]),
    "|sin_sun_elevation|": lambda i, tm: abs(i["sin_sun_elevation"]),
    "|sin_sun_azimuth|": lambda i, tm: abs(i["sin_sun_azimuth"]),
    "body_rate": lambda i, tm: i["body_rate"],
    "t_in_mode": lambda i, tm: tm,
}
_COMPARISON = re.compile(r"^(\S+) (>=|<=|>|<) (\S+)$")


def condition_value(name, inputs, t_in_mode, params):
    """Truth of the named condition."""
    if name in BOOLEAN_INPUTS:
        return bool(inputs[name])
    q, op, thr = _parse(name)
    x, y = QUANTITIES[q](inputs, t_in_mode), params[thr]
    if q == "t_in_mode":  # >= D from D - TIME_TOL; < D is its complement
        if op in (">=", ">"):
            return x >= y - TIME_TOL
        return x < y - TIME_TOL
    return {">": x > y, ">=": x >= y, "<": x < y, "<=": x <= y}[op]


def _parse(name):
    m = _COMPARISON.match(name)
    if not m or m.group(1) not in QUANTITIES or m.group(3) not in PARAMETER_DEFAULTS:
        raise ValueError(f"unknown condition {name!r}")
    return m.groups()


@dataclass(frozen=True)
class Rule:
    target: int  # the mode whose table holds the column = the mode it leads into
    column: int  # 1-based column of that table in the specification (added columns after the specification's)
    from_modes: tuple  # "Control Mode" rows marked T
    conditions: dict  # "State Values": name -> required truth (blank = absent)
    kind: str = "normal"  # "normal", "startup", "reset", "ground"
    seed_conditions: dict = None  # the literal draft, where `conditions` amends it
    added: bool = False  # a column the specification's text requires but its table does not print
    note: str = ""

    def fires(self, mode, inputs, t_in_mode, params):
        return mode in self.from_modes and all(
            condition_value(c, inputs, t_in_mode, params) == v for c, v in self.conditions.items())

    @property
    def name(self):
        return f"{MODE_NAMES[self.target]} col {self.column}"


T, F = True, False
XZ_HIGH = "xz_momentum_error > xz_momentum_error_threshold"
XZ_LOW = "xz_momentum_error <= xz_momentum_error_threshold"
MOM_HIGH = "momentum_error > spinup_momentum_error"
MOM_LOW = "momentum_error <= spinup_momentum_error"
EL_COARSE_HIGH = "|sin_sun_elevation| > coarse_elevation_error"
EL_COARSE_LOW = "|sin_sun_elevation| <= coarse_elevation_error"
AZ_COARSE_HIGH = "|sin_sun_azimuth| > coarse_azimuth_error"
AZ_COARSE_LOW = "|sin_sun_azimuth| <= coarse_azimuth_error"
WHEEL_SLOW = "|wheel_rate| < nominal_wheel_rate"
WHEEL_NOMINAL = "|wheel_rate| >= nominal_wheel_rate"
DAY, PADDLES, TRACKING = "orbit_day", "paddles_deployed", "optical_tracking"


def since(delay):  # "t - t(entered X) >= D"
    return f"t_in_mode >= {delay}"


def before(delay):  # "t - t(entered X) < D"
    return f"t_in_mode < {delay}"


RULES = (
    # ---- Table "= Wait (Mode 0)" (ACS Mode), 3 columns ----------------------------------------
    Rule(WAIT, 1, (STARTUP,), {}, kind="startup"),
    Rule(WAIT, 2, ANY, {"reset": T}, kind="reset",
         note="'Any' includes Wait: a reset in Wait re-enters Wait and restarts WMD"),
    Rule(WAIT, 3, (WAIT,), {before("WMD"): T}),
    # ---- Table "= Detumble (Mode 1)" (ACS Mode (2)), 6 columns -----------------------------------
    Rule(DETUMBLE, 1, (WAIT,), {since("WMD"): T}),
    Rule(DETUMBLE, 2, (DETUMBLE,), {before("DMD"): T}),
    Rule(DETUMBLE, 3, (DETUMBLE,), {before("DMD"): F, XZ_HIGH: T}),
    Rule(DETUMBLE, 4, (SPINUP,), {XZ_HIGH: T, since("SMD"): T, PADDLES: F}),
    Rule(DETUMBLE, 5, (SPINUP,), {XZ_HIGH: T, since("SMD"): T, TRACKING: F}),
    Rule(DETUMBLE, 6, (GROUND_COMMAND,), {since("GCMD"): T}),
    # ---- Table "= Spinup (Mode 2)" (ACS Mode (3)), 9 columns -------------------------------------
    Rule(SPINUP, 1, (DETUMBLE,), {since("DMD"): T, XZ_LOW: T}),
    Rule(SPINUP, 2, (SPINUP,), {before("SMD"): T, PADDLES: F, TRACKING: F}),
    Rule(SPINUP, 3, (SPINUP,), {XZ_LOW: T, before("SMD"): F, PADDLES: F, TRACKING: F, MOM_HIGH: T}),
    Rule(SPINUP, 4, (SPINUP,), {XZ_LOW: T, before("SMD"): F, PADDLES: F, TRACKING: F, DAY: F}),
    Rule(SPINUP, 5, (REORIENT,), {DAY: F}),
    Rule(SPINUP, 6, (REORIENT,), {MOM_HIGH: T, DAY: T, since("RMD"): T}),
    Rule(SPINUP, 7, (ACQUIRE,), {DAY: F}),
    Rule(SPINUP, 8, (ORBIT_DAY,), {TRACKING: F, DAY: F},
         note="after A2 this co-fires with Orbit Night col 2 when tracking is lost at night "
              "after ODMD: a conflict, resolved to Spinup (uncertain), this column's target"),
    Rule(SPINUP, 9, (ORBIT_NIGHT,), {TRACKING: T, DAY: F, "body_rate > max_tumble_rate": T,
                                     "|sin_sun_azimuth| > fine_azimuth_error": F,
                                     "|sin_sun_elevation| > fine_elevation_error": F}),
    # ---- Table "= Reorient (Mode 3)" (ACS Mode (4)), 5 columns -----------------------------------
    Rule(REORIENT, 1, (SPINUP,), {since("SMD"): T, XZ_LOW: T, MOM_HIGH: F, DAY: T, PADDLES: F}),
    Rule(REORIENT, 2, (SPINUP,), {since("SMD"): T, XZ_LOW: T, MOM_HIGH: F, DAY: T, TRACKING: F}),
    Rule(REORIENT, 3, (REORIENT,), {DAY: T, since("RMD"): T},
         note="hold after RMD in daylight while no exit (cols Spinup 6, Deploy Wheel 1, Acquire 1) "
              "fires, i.e. while the Sun elevation is still beyond the coarse error"),
    Rule(REORIENT, 4, (REORIENT,), {MOM_HIGH: F, since("RMD"): F, EL_COARSE_HIGH: T},
         note="literal: before RMD Reorient holds only while the elevation is beyond the coarse "
              "error; reaching it earlier, or a momentum error in daylight, matches no rule (Spinup)"),
    Rule(REORIENT, 5, (ACQUIRE,), {DAY: T, EL_COARSE_HIGH: T, since("AMD"): T}),
    # ---- Table "= Deploy Wheel (Mode 4)" (ACS Mode (5)), 2 columns -------------------------------
    Rule(DEPLOY_WHEEL, 1, (REORIENT,), {since("RMD"): T, DAY: T, MOM_HIGH: F, EL_COARSE_HIGH: F, WHEEL_SLOW: T},
         seed_conditions={since("RMD"): T, DAY: T, MOM_HIGH: T, EL_COARSE_HIGH: T, WHEEL_SLOW: T},
         note="A1: the draft's momentum and elevation rows read '>' with T; read as '<=' (F). "
              "Literally this column always co-fires with Spinup col 6 (Reorient, momentum error, "
              "day, RMD), so Deploy Wheel could never be entered; and Reorient's goal is a small "
              "elevation. Read so, it is Acquire col 1 with the wheel below its nominal rate."),
    Rule(DEPLOY_WHEEL, 2, (DEPLOY_WHEEL,), {before("DWMD"): T}),
    # ---- Table "= Acquire (Mode 5)" (ACS Mode (6)), 8 columns ------------------------------------
    Rule(ACQUIRE, 1, (REORIENT,), {since("RMD"): T, DAY: T, MOM_LOW: T, EL_COARSE_LOW: T, WHEEL_NOMINAL: T}),
    Rule(ACQUIRE, 2, (ACQUIRE,), {DAY: T, before("AMD"): T}),
    Rule(ACQUIRE, 3, (ACQUIRE,), {DAY: T, EL_COARSE_LOW: T, before("AMD"): F, AZ_COARSE_HIGH: T}),
    Rule(ACQUIRE, 4, (DEPLOY_WHEEL,), {since("DWMD"): T}),
    Rule(ACQUIRE, 5, (DEPLOY_PADDLES,), {PADDLES: T}),
    Rule(ACQUIRE, 6, (DEPLOY_PADDLES,), {PADDLES: F, since("DPMD"): T}),
    Rule(ACQUIRE, 7, (ORBIT_DAY,), {DAY: T, EL_COARSE_LOW: T, AZ_COARSE_HIGH: T, since("ODMD"): T}),
    Rule(ACQUIRE, 8, (ORBIT_DAY,), {EL_COARSE_LOW: T, AZ_COARSE_HIGH: T, TRACKING: T}),
    # ---- Table "= Deploy Paddles (Mode 6)" (ACS Mode (7)), 2 columns -----------------------------
    Rule(DEPLOY_PADDLES, 1, (ACQUIRE,), {since("AMD"): T, DAY: T, EL_COARSE_LOW: T, AZ_COARSE_LOW: T, PADDLES: F}),
    Rule(DEPLOY_PADDLES, 2, (DEPLOY_PADDLES,), {PADDLES: F, before("DPMD"): T}),
    # ---- Table "= Orbit Day (Mode 7)" (ACS Mode (8)), 6 columns ----------------------------------
    Rule(ORBIT_DAY, 1, (ACQUIRE,), {since("AMD"): T, DAY: T, EL_COARSE_LOW: T, AZ_COARSE_LOW: T, PADDLES: T}),
    Rule(ORBIT_DAY, 2, (ORBIT_NIGHT,), {DAY: T, "|sin_sun_elevation| >= fine_elevation_error": T},
         note="the draft's garbled '=>' read as '>=', the complement of Orbit Night col 4's '<'"),
    Rule(ORBIT_DAY, 3, (ORBIT_NIGHT,), {DAY: T, "|sin_sun_azimuth| >= fine_azimuth_error": T},
         note="'=>' read as '>=' (see col 2)"),
    Rule(ORBIT_DAY, 4, (ORBIT_NIGHT,), {DAY: T, TRACKING: T}),
    Rule(ORBIT_DAY, 5, (ORBIT_DAY,), {DAY: T, before("ODMD"): T},
         seed_conditions={DAY: T, TRACKING: T, before("ODMD"): T},
         note="A5: the draft also requires tracking. Then Orbit Day entered without tracking (from "
              "Acquire in daylight, the usual case) matches no rule and falls to Spinup at once; "
              "every other '< delay' hold (Acquire col 2: day, < AMD) has only the delay."),
    Rule(ORBIT_DAY, 6, (ORBIT_DAY,), {DAY: T, EL_COARSE_LOW: T, AZ_COARSE_LOW: T, TRACKING: F, before("ODMD"): F}),
    # ---- Table "= Orbit Night (Mode 8)" (ACS Mode (9)), 4 columns --------------------------------
    Rule(ORBIT_NIGHT, 1, (SPINUP,), {PADDLES: T, TRACKING: T, since("SMD"): T},
         seed_conditions={PADDLES: T, TRACKING: T},
         note="A3: SMD added. Every other exit from Spinup waits SMD (Detumble 4-5, Reorient 1-2); "
              "without it a tumble at night alternates Orbit Night -> Spinup (col 9) -> Orbit Night "
              "at every evaluation."),
    Rule(ORBIT_NIGHT, 2, (ORBIT_DAY,), {since("ODMD"): T, DAY: F, EL_COARSE_LOW: T, AZ_COARSE_LOW: T},
         seed_conditions={since("ODMD"): T, DAY: T, EL_COARSE_LOW: T, AZ_COARSE_LOW: T},
         note="A2: the draft's 'Orbit in-state day T' read as F (night falls). Literally Orbit Day "
              "would go to Orbit Night in daylight after ODMD, and Orbit Day's own hold col 6 "
              "(day, coarse errors, after ODMD) could never apply."),
    Rule(ORBIT_NIGHT, 3, (ORBIT_DAY,), {TRACKING: T, since("ODMD"): T, EL_COARSE_LOW: T, AZ_COARSE_LOW: T},
         note="literal, no day condition: with the optical system tracking in daylight Orbit Day "
              "goes to Orbit Night after ODMD and Orbit Day col 4 brings it back (a 10 s cycle)"),
    Rule(ORBIT_NIGHT, 4, (ORBIT_NIGHT,), {TRACKING: T, DAY: F, "body_rate <= max_tumble_rate": T,
                                          "|sin_sun_azimuth| < fine_azimuth_error": T,
                                          "|sin_sun_elevation| < fine_elevation_error": T}),
    # ---- Table "= Ground Command (Mode 9)", 1 column ("Received ground control command: T") ------
    Rule(GROUND_COMMAND, 1, tuple(m for m in MODES if m != WAIT), {"ground_command": T}, kind="ground",
         note="from any mode but Wait (see col 2); a command in Ground Command restarts GCMD"),
    Rule(GROUND_COMMAND, 2, (WAIT,), {"ground_command": T, since("WMD"): T}, kind="ground", added=True,
         note="A6: in Wait a command is accepted only once WMD elapsed (Wait lets the sensors "
              "settle after startup/reset; the software never leaves Wait before WMD)"),
    Rule(GROUND_COMMAND, 3, (GROUND_COMMAND,), {since("GCMD"): F}, added=True,
         note="A4: hold. The draft prints no hold, so Ground Command would fall to Spinup at the "
              "next evaluation; its text says it stays until no command came for GCMD (Detumble col 6)"),
)

AMENDMENTS = {
    "A1": "Deploy Wheel col 1: momentum and elevation read as <= (the draft's T under '>' makes the mode unreachable)",
    "A2": "Orbit Night col 2: orbit day F instead of T",
    "A3": "Orbit Night col 1: t_in_mode >= SMD added",
    "A4": "Ground Command: hold while t_in_mode < GCMD added",
    "A5": "Orbit Day col 5: optical tracking dropped from the < ODMD hold",
    "A6": "Ground Command from Wait only after WMD",
}

# Actuator permissions per mode, from the specification's descriptions (coils_enabled, wheel_enabled,
# paddle_deploy). wheel_enabled: the wheel is under control (holding or changing its speed);
# false: commanded to zero torque.
PERMISSIONS = {
    WAIT: (F, F, F),            # "none of the actuators should be active"
    DETUMBLE: (T, T, F),        # Y moment damps X/Z rates; wheel keeps its entry speed
    SPINUP: (T, T, F),          # X/Z moments spin up, Y nutation damping; wheel held (not stated)
    REORIENT: (T, T, F),        # X/Z moments on elevation, Y nutation damping; wheel held (not stated)
    DEPLOY_WHEEL: (F, T, F),    # "no torquing ... via the torque coils"; wheel spun up
    ACQUIRE: (T, T, F),         # coarse attitude corrections
    DEPLOY_PADDLES: (F, T, T),  # "cuts all magnetic moments to zero, ... maintain the wheel velocity, deploys"
    ORBIT_DAY: (T, T, F),       # "same control behavior as mode 5"
    ORBIT_NIGHT: (T, T, F),     # as Orbit Day, attitude from the optical system
    GROUND_COMMAND: (T, T, F),  # ground uplinks commands; paddles deploy only in mode 6 (our choice)
}


def _check_tables(rules):
    keys = set()
    for r in rules:
        if (r.target, r.column) in keys:
            raise ValueError(f"duplicate rule {r.name}")
        keys.add((r.target, r.column))
        for c in r.conditions:
            if c not in BOOLEAN_INPUTS:
                q, _, thr = _parse(c)
                if thr in DELAY_MODE and r.from_modes != (DELAY_MODE[thr],):
                    raise ValueError(f"{r.name}: delay {thr} of {MODE_NAMES[DELAY_MODE[thr]]} from other modes")


_check_tables(RULES)


def literal_rules():
    """The rules as the draft prints them (amendments undone, added columns dropped)."""
    out = []
    for r in RULES:
        if r.added:
            continue
        if r.seed_conditions is not None:
            r = Rule(r.target, r.column, r.from_modes, dict(r.seed_conditions), r.kind)
        out.append(r)
    return tuple(out)


# ---- checks -------------------------------------------------------------------------------
def check_parameters(params=None):
    """Defaults completed with `params`; ValueError naming a bad parameter and its range."""
    p = finite_parameters(PARAMETER_DEFAULTS, params)
    for k, v in p.items():
        if k in DELAYS:
            if v < 0:
                raise ValueError(f"parameter {k} = {v!r} s must be in [0, inf)")
        elif k in UNIT_PARAMETERS:
            if not 0 < v <= 1:
                raise ValueError(f"parameter {k} = {v!r} must be in (0, 1] (a sine)")
        elif v <= 0:
            raise ValueError(f"parameter {k} = {v!r} must be in (0, inf)")
    for what in ("elevation", "azimuth"):
        if p[f"fine_{what}_error"] > p[f"coarse_{what}_error"]:
            raise ValueError(f"parameter fine_{what}_error = {p[f'fine_{what}_error']!r} must be in "
                             f"(0, coarse_{what}_error = {p[f'coarse_{what}_error']!r}]")
    return p


def check_inputs(inputs=None):
    """Defaults completed with `inputs`; ValueError naming a bad input and its range."""
    i = dict(INPUT_DEFAULTS)
    for k, v in (inputs or {}).items():
        if k not in i:
            raise ValueError(f"unknown input {k!r}")
        i[k] = v
    for k in i:
        if k in BOOLEAN_INPUTS:
            i[k] = bool(i[k])
            continue
        v = float(i[k])
        if not math.isfinite(v):
            raise ValueError(f"input {k} = {v!r} must be finite")
        if k in ("xz_momentum_error", "momentum_error", "body_rate") and v < 0:
            raise ValueError(f"input {k} = {v!r} is a magnitude, must be in [0, inf)")
        if k.startswith("sin_") and abs(v) > 1.0 + 1e-12:
            raise ValueError(f"input {k} = {v!r} is a sine, must be in [-1, 1]")
        i[k] = v
    return i


# ---- decisions ----------------------------------------------------------------------------
@dataclass
class Decision:
    mode: int  # the mode after the decision
    rule: Rule = None  # the rule that decided (None: uncertain fallback)
    enter: bool = False  # the mode is (re-)entered: its timer restarts
    uncertain: bool = False
    fired: list = field(default_factory=list)  # every rule that fired


def decide(mode, t_in_mode, inputs, params, rules=RULES):
    """The decision from `mode` after `t_in_mode` s with `inputs` (checked dicts); see the
    module docstring for the priority."""
    fired = [r for r in rules if r.fires(mode, inputs, t_in_mode, params)]
    for kind in ("startup", "reset", "ground"):
        hits = [r for r in fired if r.kind == kind]
        if hits:
            return Decision(hits[0].target, hits[0], True, False, fired)
    normal = [r for r in fired if r.kind == "normal"]
    out = [r for r in normal if r.target != mode]
    if out:
        if len({r.target for r in out}) == 1:
            return Decision(out[0].target, out[0], True, False, fired)
        return Decision(SAFE_MODE, None, mode != SAFE_MODE, True, fired)  # conflict
    holds = [r for r in normal if r.target == mode]
    if holds:
        return Decision(mode, holds[0], False, False, fired)
    return Decision(SAFE_MODE, None, mode != SAFE_MODE, True, fired)  # no rule


class AcsModeManager:
    """The mode state machine. State: mode, time the mode was entered, model time, the last
    decision's rule and uncertainty."""

    def __init__(self, params=None, t0=0.0, rules=RULES):
        self.params = check_parameters(params)
        self.rules = rules
        t0 = float(t0)
        if not math.isfinite(t0):
            raise ValueError(f"start time {t0!r} must be finite")
        d = decide(STARTUP, 0.0, check_inputs(), self.params, rules)  # Startup -> Wait
        self.t = t0
        self._apply(d, t0)

    def _apply(self, d, t):
        if d.enter:
            self.t_entered = t
        self.mode = d.mode
        self.uncertain = d.uncertain
        self.rule = None if d.rule is None else (d.rule.target, d.rule.column)

    @property
    def time_in_mode(self):
        return self.t - self.t_entered

    @property
    def permissions(self):
        """(coils_enabled, wheel_enabled, paddle_deploy) of the current mode."""
        return PERMISSIONS[self.mode]

    def step(self, t, h, inputs=None):
        """Decide at communication point t with the inputs present; the mode holds over
        [t, t + h]. Returns the Decision."""
        t, h = float(t), float(h)
        if not (math.isfinite(t) and math.isfinite(h) and h >= 0):
            raise ValueError(f"step (t = {t!r}, h = {h!r}) must be finite with h >= 0")
        if t < self.t_entered - TIME_TOL:
            raise ValueError(f"time {t!r} s is before the current mode was entered ({self.t_entered!r} s)")
        d = decide(self.mode, t - self.t_entered, check_inputs(inputs), self.params, self.rules)
        self._apply(d, t)
        self.t = t + h
        return d

    def get_state(self):
        return {"mode": self.mode, "t": self.t, "t_entered": self.t_entered,
                "uncertain": self.uncertain, "rule": None if self.rule is None else list(self.rule)}

    def set_state(self, state):
        mode = int(state["mode"])
        if mode not in MODES:
            raise ValueError(f"mode {mode!r} must be in 0..9 ({MODE_TABLE})")
        self.mode = mode
        self.t = float(state["t"])
        self.t_entered = float(state["t_entered"])
        self.uncertain = bool(state.get("uncertain", False))
        rule = state.get("rule")
        self.rule = None if rule is None else (int(rule[0]), int(rule[1]))
