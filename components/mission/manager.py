"""NEIGHBOR's mission manager: the operating modes of thesis section 3.4 (Figure 45), what each
mode powers (sections 3.5-3.6, Tables 5-7) and the de-orbit sub-phases (sections 3.3, 3.5 and
Appendix I).

Modes (`mode`):
  1 IDLE            microprocessor quiescent, woken wake_duration (5 s) every wake_period (1 day)
                    to check the host's heartbeat; a check that finds no heartbeat -> GRACE
  2 GRACE           grace period (fixed, default 30 days) from the check that found the heartbeat
                    missing; the daily checks continue, a heartbeat found again -> IDLE; at its
                    end -> AWAITING
  3 AWAITING        grace period over: microprocessor nominal, waiting for a ground contact
                    (ground_contact -> CONTACT; a returning heartbeat -> IDLE)
  4 CONTACT         final contact: UHF receive and transmit on (host status downlink, thesis
                    requirement 2); ground_command during the contact is latched; at the end of
                    the contact -> DEORBIT if it was latched, else back to AWAITING (Appendix I
                    leaves the confirmation loop when the contact ends)
  5 DEORBIT         sub-phases (`phase`): 1 attitude determination (a fixed
                    attitude_determination_duration, 600 s, longer until the input
                    attitude_valid holds, e.g. the estimator's first fix after an eclipse; after
                    attitude_determination_timeout, if > 0, the detumble starts anyway: it needs
                    rates only), 2 detumble (until detumble_done),
                    3 slew to the burn attitude (until slew_done), 4 burn with the attitude held
                    by the tracking controller (until budget_spent) -> MONITORING.
                    Fault management: a detumble or slew that has not finished after
                    detumble_timeout / slew_timeout (600 s each; 0: none) is retried
                    (phase_retries times, default 1: the phase starts over with a fresh timer),
                    then the mission continues with the next phase: a slew from a tumble not
                    fully damped, or the burn with the tracking controller pulling the attitude
                    in. Never waiting until the battery is empty; `detumble_timeouts` and
                    `slew_timeouts` count what happened. The thesis' phases end long before.
                    With `safe_without_attitude`, a slew or burn is never started without
                    attitude_valid (a burn in an unknown direction may raise the orbit): a
                    detumble or slew that is done goes on (its controller holding the spacecraft)
                    until the attitude is valid, e.g. while the estimate settles after a fast
                    detumble; if it times out without one, the de-orbit is abandoned for
                    MONITORING, the safe state (no thrust, the position beaconed in contacts for
                    the operators), with `safe_reason` 1. This is where a determination timeout
                    (no Sun sensor left) ends after the detumble.
  6 MONITORING      microprocessor quiescent; during ground contacts GPS + UHF on to beacon the
                    position (and downlink stored data) until the battery is empty or re-entry.
                    beacon_interval (default 0: every contact, as Appendix I) lets operators
                    choose the beacon frequency (section 3.6): a contact is used only if it
                    starts at least beacon_interval after the start of the last one used
  7 END             battery empty (state_of_charge <= battery_empty_soc) or re-entered
                    (`end_reason` 1 or 2); everything off. Either condition ends the mission
                    from any mode: without power nothing runs, after re-entry nothing is left.

Timing semantics (co-simulation). do_step(t, h) decides from the inputs at the start of the
step (held over [t, t + h), zero-order hold): every output is state, none depends directly on
an input. Internal timed events (wake start/end, grace end, end of attitude determination)
happen at their exact times inside the step; `next_event_time` announces the next one so that a
master can end a step on it, and a step that ends on an event's time (within TIME_TOL) leaves
the outputs already in the new state. A heartbeat check happens at every step start where the
microprocessor is awake, and at the start of every wake window that begins inside a step (with
the held input), so a daily check is never skipped, even by steps of hours or days, and the
grace period starts at the exact check time. Input conditions (contacts, confirmation,
detumble/slew/burn done, battery, re-entry) are evaluated at step starts only, so a change they
cause shows on the outputs one step later. A completion flag of a de-orbit phase
(detumble_done, slew_done, budget_spent) is honoured only at a step start after the end of the
step that first output the phase, i.e. once its controller has had at least one whole step
with its enable on, so a stale flag cannot skip a phase.

Power states follow Appendix I where the thesis text and tables differ:
- Table 6 lists its last seven power values one row off: awaiting final contact 0.0221 W
  (microprocessor only, as in Appendix I), final contact 2.84 W (microprocessor + UHF Rx + Tx),
  attitude determination 1.67 W (microprocessor + horizon + Sun + gyro + GPS), attitude control
  and de-orbit maneuver 2.17 W (+ propulsion), monitoring quiescent 9.24e-8 W, monitoring
  downlink 4.21 W (microprocessor + UHF Rx + Tx + GPS): these sums of Table 5 match the
  printed values shifted by one row.
- Section 3.5 says the propulsion system is powered already for attitude determination;
  Appendix I (and 1.67 W) power it only from the attitude control maneuvers: followed here.
- Section 3.5 says the UHF transceiver is on for the whole wait for confirmation; Appendix I
  powers the radio only during the contact: default here, `listen_while_awaiting` switches
  the receiver on while awaiting.
"""
import math

from ..core.constants import DAY
from .modes import MODE_TABLE, PHASE_TABLE, DeorbitPhase, EndReason, MissionMode
from .power_bus import LOAD_NAMES

# The mode logic below reads best with bare names: one per enum member, in value order.
IDLE, GRACE, AWAITING, CONTACT, DEORBIT, MONITORING, END = MissionMode
PHASE_NONE, ATTITUDE_DETERMINATION, DETUMBLE, SLEW, BURN = DeorbitPhase
END_NONE, END_BATTERY, END_REENTERED = EndReason
SAFE_NONE, SAFE_NO_ATTITUDE = 0, 1  # safe_reason: why the de-orbit was abandoned for the safe state

NO_EVENT = 1e300  # next_event_time when nothing is scheduled

# The Boolean outputs besides the power-bus loads (components.mission.power_bus), in output order.
COMMANDS = ("detumble_enable", "slew_enable", "tracking_enable", "burn_enable", "data_recording",
            "downlink_enable")

PARAMETER_DEFAULTS = {
    "grace_period": 30 * DAY,
    "wake_period": DAY,
    "wake_duration": 5.0,
    "wake_offset": 0.0,
    "attitude_determination_duration": 600.0,
    "battery_empty_soc": 0.0,
    "initial_mode": IDLE,
    "initial_phase": ATTITUDE_DETERMINATION,
    "listen_while_awaiting": False,
    "beacon_interval": 0.0,
    "detumble_timeout": 600.0,
    "slew_timeout": 600.0,
    "phase_retries": 1,
    "attitude_determination_timeout": 0.0,
    "safe_without_attitude": False,
}
INPUT_DEFAULTS = {
    "heartbeat": True, "ground_contact": False, "ground_command": False, "detumble_done": False,
    "slew_done": False, "budget_spent": False, "state_of_charge": 1.0, "reentered": False,
    "attitude_valid": True,
}


def time_tol(t):
    """Two times closer than this are the same instant (a master's t + (t_event - t) may miss
    t_event by a few ulp)."""
    return 1e-6 + 1e-14 * abs(t)


def check_parameters(params):
    """Full parameter dict from defaults + `params`; ValueError naming a bad or unknown one."""
    unknown = set(params) - set(PARAMETER_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown mission-manager parameter(s) {sorted(unknown)}; known: "
                         f"{sorted(PARAMETER_DEFAULTS)}")
    p = dict(PARAMETER_DEFAULTS, **params)
    for name in ("grace_period", "wake_period", "wake_duration", "wake_offset", "attitude_determination_duration",
                 "battery_empty_soc", "beacon_interval", "detumble_timeout", "slew_timeout",
                 "attitude_determination_timeout"):
        try:
            p[name] = float(p[name])
        except (TypeError, ValueError):
            raise ValueError(f"{name} = {p[name]!r} must be a number") from None
        if not math.isfinite(p[name]):
            raise ValueError(f"{name} = {p[name]!r} must be finite")
    if p["grace_period"] < 0:
        raise ValueError(f"grace_period = {p['grace_period']!r} s must be >= 0")
    if p["wake_period"] <= 0:
        raise ValueError(f"wake_period = {p['wake_period']!r} s must be > 0")
    if not 0 < p["wake_duration"] < p["wake_period"]:
        raise ValueError(f"wake_duration = {p['wake_duration']!r} s must be in (0, wake_period = "
                         f"{p['wake_period']!r} s)")
    if not 0 <= p["wake_offset"] < p["wake_period"]:
        raise ValueError(f"wake_offset = {p['wake_offset']!r} s must be in [0, wake_period = {p['wake_period']!r} s)")
    if p["attitude_determination_duration"] < 0:
        raise ValueError(f"attitude_determination_duration = {p['attitude_determination_duration']!r} s must be >= 0")
    if p["beacon_interval"] < 0:
        raise ValueError(f"beacon_interval = {p['beacon_interval']!r} s must be >= 0 (0: beacon in every contact)")
    for name in ("detumble_timeout", "slew_timeout", "attitude_determination_timeout"):
        if p[name] < 0:
            raise ValueError(f"{name} = {p[name]!r} s must be >= 0 (0: no timeout)")
    if isinstance(p["phase_retries"], bool) or not float(p["phase_retries"]).is_integer() or p["phase_retries"] < 0:
        raise ValueError(f"phase_retries = {p['phase_retries']!r} must be an integer >= 0")
    p["phase_retries"] = int(p["phase_retries"])
    if not 0 <= p["battery_empty_soc"] < 1:
        raise ValueError(f"battery_empty_soc = {p['battery_empty_soc']!r} must be in [0, 1)")
    if p["initial_mode"] not in (IDLE, GRACE, AWAITING, CONTACT, DEORBIT, MONITORING):
        raise ValueError(f"initial_mode = {p['initial_mode']!r} must be one of 1..6 ({MODE_TABLE})")
    if p["initial_phase"] not in (ATTITUDE_DETERMINATION, DETUMBLE, SLEW, BURN):
        raise ValueError(f"initial_phase = {p['initial_phase']!r} must be one of 1..4 ({PHASE_TABLE})")
    p["initial_mode"], p["initial_phase"] = int(p["initial_mode"]), int(p["initial_phase"])
    p["listen_while_awaiting"] = bool(p["listen_while_awaiting"])
    p["safe_without_attitude"] = bool(p["safe_without_attitude"])
    return p


def check_inputs(inputs):
    unknown = set(inputs) - set(INPUT_DEFAULTS)
    if unknown:
        raise ValueError(f"unknown mission-manager input(s) {sorted(unknown)}; known: {sorted(INPUT_DEFAULTS)}")
    x = dict(INPUT_DEFAULTS, **inputs)
    soc = float(x["state_of_charge"])
    if not math.isfinite(soc):
        raise ValueError(f"state_of_charge = {soc!r} must be finite")
    x = {k: bool(v) for k, v in x.items() if k != "state_of_charge"}
    x["state_of_charge"] = soc
    return x


class MissionManager:
    """The mode machine. `step(t, h, inputs)` advances it over [t, t + h]; `mode`, `phase`,
    `powered()`, `next_event_time`, `time_in_mode` describe the state at the model's time `t`."""

    def __init__(self, params=None, t0=0.0):
        self.p = check_parameters(params or {})
        t0 = float(t0)
        if not math.isfinite(t0):
            raise ValueError(f"start time = {t0!r} must be finite")
        self.t = t0
        self.mode, self.phase, self.end_reason = None, PHASE_NONE, END_NONE
        self.mode_entry = self.phase_entry = t0
        self.awake, self.wake_end, self.next_wake_k = False, NO_EVENT, 0
        self.grace_end = self.att_det_end = NO_EVENT
        self.att_det_waiting = False  # determination time over, waiting for a valid attitude
        self.confirmed = False  # ground_command latched during the current final contact
        self.in_contact = False  # monitoring: beaconing in the contact sampled at the last step start
        self.contact_seen = False  # monitoring: ground_contact at the last step start
        self.last_beacon = None  # monitoring: start of the last contact used for a beacon
        self.heartbeat_lost_at = NO_EVENT  # time of the check that found the heartbeat missing
        self.detumble_timeouts = self.slew_timeouts = 0  # phase timeouts so far (retries included)
        self.determination_timeouts = 0
        self.safe_reason = SAFE_NONE
        self.attempt = 0  # retries of the current phase
        self.phase_published = t0  # end of the step that first output the current phase
        mode = self.p["initial_mode"]
        self._enter(mode, t0)
        if mode == DEORBIT:
            self._enter_phase(self.p["initial_phase"], t0)
        self.phase_published = t0

    # ---- wake schedule (IDLE and GRACE) ----------------------------------------------------
    def _window_start(self, k):
        return self.p["wake_offset"] + k * self.p["wake_period"]

    def _reset_wake_schedule(self, t):
        """Wake state at time t: awake if t lies in a window [start, start + duration)."""
        P, d = self.p["wake_period"], self.p["wake_duration"]
        k = math.floor((t - self.p["wake_offset"]) / P)
        if self._window_start(k + 1) <= t + time_tol(t):  # t on the next start (rounding of the floor)
            k += 1
        start = self._window_start(k)
        self.awake = t < start + d - time_tol(t)
        self.wake_end = start + d if self.awake else NO_EVENT
        self.next_wake_k = k + 1

    # ---- transitions -----------------------------------------------------------------------
    def _enter(self, mode, t):
        previous = self.mode
        self.mode, self.mode_entry = mode, t
        self.phase, self.phase_entry = PHASE_NONE, t
        self.phase_published = None
        self.confirmed = False
        self.in_contact = False
        self.grace_end = self.att_det_end = NO_EVENT
        if mode in (IDLE, GRACE):
            if previous not in (IDLE, GRACE):  # from IDLE <-> GRACE the daily schedule runs on
                self._reset_wake_schedule(t)
        else:
            self.awake, self.wake_end = False, NO_EVENT
        if mode == GRACE:
            self.heartbeat_lost_at = t
            self.grace_end = t + self.p["grace_period"]
        elif mode == DEORBIT:
            self._enter_phase(ATTITUDE_DETERMINATION, t)

    def _enter_phase(self, phase, t, retry=False):
        self.attempt = self.attempt + 1 if retry else 0
        self.phase, self.phase_entry = phase, t
        self.phase_published = None  # set at the end of this step
        self.att_det_end = t + self.p["attitude_determination_duration"] if phase == ATTITUDE_DETERMINATION \
            else NO_EVENT
        self.att_det_waiting = False

    def _check_heartbeat(self, t, heartbeat):
        if self.mode == IDLE and not heartbeat:
            self._enter(GRACE, t)
        elif self.mode == GRACE and heartbeat:
            self._enter(IDLE, t)

    def _evaluate_inputs(self, t, x):
        """Input-driven transitions at a step start t."""
        if self.mode == END:
            return
        if x["reentered"]:
            self._enter(END, t)
            self.end_reason = END_REENTERED
            return
        if x["state_of_charge"] <= self.p["battery_empty_soc"]:
            self._enter(END, t)
            self.end_reason = END_BATTERY
            return
        mode = self.mode
        if mode in (IDLE, GRACE):
            if self.awake:
                self._check_heartbeat(t, x["heartbeat"])
        elif mode in (AWAITING, CONTACT) and x["heartbeat"]:
            self._enter(IDLE, t)  # the host recovered: no de-orbit
        elif mode == AWAITING:
            if x["ground_contact"]:
                self._enter(CONTACT, t)
                self.confirmed = x["ground_command"]
        elif mode == CONTACT:
            if x["ground_contact"]:
                self.confirmed = self.confirmed or x["ground_command"]
            elif self.confirmed:
                self._enter(DEORBIT, t)
            else:
                self._enter(AWAITING, t)
        elif mode == DEORBIT:
            # the controller has had a whole step with its enable on
            started = self.phase_published is not None and self.phase_published < t - time_tol(t)
            if self.phase == ATTITUDE_DETERMINATION and self.att_det_waiting and x["attitude_valid"]:
                self._enter_phase(DETUMBLE, t)
            elif started and self.phase == DETUMBLE and x["detumble_done"] and self._attitude_ok(x):
                self._enter_phase(SLEW, t)
            elif started and self.phase == SLEW and x["slew_done"] and self._attitude_ok(x):
                self._enter_phase(BURN, t)
            elif started and self.phase == BURN and x["budget_spent"]:
                self._enter_monitoring(t, x["ground_contact"])
        elif mode == MONITORING:
            self._monitor_contact(t, x["ground_contact"])

    def _attitude_ok(self, x):
        """A slew or burn may start: the attitude is valid, or safe_without_attitude is off."""
        return x["attitude_valid"] or not self.p["safe_without_attitude"]

    def _maneuver(self, phase, t, x):
        """Into the slew or the burn after a phase timeout; without a valid attitude (and
        safe_without_attitude), the safe state instead."""
        if self._attitude_ok(x):
            self._enter_phase(phase, t)
        else:
            self._enter_monitoring(t, x["ground_contact"])
            self.safe_reason = SAFE_NO_ATTITUDE

    def _enter_monitoring(self, t, contact):
        self._enter(MONITORING, t)
        self.contact_seen = False
        self._monitor_contact(t, contact)

    def _monitor_contact(self, t, contact):
        """Beacon in this contact? Decided when it starts, from beacon_interval."""
        if contact and not self.contact_seen:
            interval = self.p["beacon_interval"]
            self.in_contact = (self.last_beacon is None or interval <= 0.0
                               or t - self.last_beacon >= interval - time_tol(t))
            if self.in_contact:
                self.last_beacon = t
        elif not contact:
            self.in_contact = False
        self.contact_seen = contact

    def _next_event(self):
        """(time, kind) of the next timed event, or (NO_EVENT, None)."""
        events = []
        if self.mode in (IDLE, GRACE):
            if self.awake:
                events.append((self.wake_end, 0, "wake_end"))
            events.append((self._window_start(self.next_wake_k), 1, "wake_start"))
            if self.mode == GRACE:
                events.append((self.grace_end, 2, "grace_end"))
        elif self.mode == DEORBIT and self.phase == ATTITUDE_DETERMINATION:
            if not self.att_det_waiting:
                events.append((self.att_det_end, 3, "att_det_end"))
            elif self.p["attitude_determination_timeout"] > 0:
                events.append((self.phase_entry + self.p["attitude_determination_timeout"], 3, "att_det_timeout"))
        elif self.mode == DEORBIT and self.phase in (DETUMBLE, SLEW):
            limit = self.p["detumble_timeout" if self.phase == DETUMBLE else "slew_timeout"]
            if limit > 0:
                events.append((self.phase_entry + limit, 4, "phase_timeout"))
        if not events:
            return NO_EVENT, None
        time, _, kind = min(events)
        return time, kind

    @property
    def next_event_time(self):
        return self._next_event()[0]

    def step(self, t, h, inputs):
        """Advance over [t, t + h] with `inputs` (dict, names of INPUT_DEFAULTS) held from t.
        If the model's own time lags t (a master that suspended it), the skipped span is
        covered too, with the same held inputs."""
        t, h = float(t), float(h)
        if not (math.isfinite(t) and math.isfinite(h) and h >= 0):
            raise ValueError(f"step from t = {t!r} s by h = {h!r} s: both must be finite, h >= 0")
        if t < self.t - time_tol(self.t):
            raise ValueError(f"step starts at t = {t!r} s, before the manager's time {self.t!r} s "
                             "(restore an earlier FMU state to go back)")
        x = check_inputs(inputs)
        t_end = t + h
        start = min(t, self.t)
        self.t = start
        self._evaluate_inputs(start, x)
        end_tol = time_tol(t_end)
        while True:
            te, kind = self._next_event()
            if kind is None or te > t_end + end_tol:
                break
            te = max(te, start)
            self.t = te
            if kind == "wake_end":
                self.awake, self.wake_end = False, NO_EVENT
            elif kind == "wake_start":
                self.awake = True
                self.wake_end = te + self.p["wake_duration"]
                self.next_wake_k += 1
                if te < t_end - end_tol:  # a window starting inside the step: check now
                    self._check_heartbeat(te, x["heartbeat"])
            elif kind == "grace_end":
                self._enter(AWAITING, te)
            elif kind == "att_det_end":
                if x["attitude_valid"]:
                    self._enter_phase(DETUMBLE, te)
                else:  # no attitude yet (e.g. no Sun in eclipse): wait for it, or for the timeout
                    self.att_det_waiting = True
            elif kind == "att_det_timeout":  # the documented fallback: the detumble needs rates only
                self.determination_timeouts += 1
                self._enter_phase(DETUMBLE, te)
            elif kind == "phase_timeout":
                if self.phase == DETUMBLE:
                    self.detumble_timeouts += 1
                else:
                    self.slew_timeouts += 1
                if self.attempt < self.p["phase_retries"]:
                    self._enter_phase(self.phase, te, retry=True)
                else:  # the documented fallback: on with the next phase
                    self._maneuver(SLEW if self.phase == DETUMBLE else BURN, te, x)
        self.t = max(t_end, self.t)
        if self.phase_published is None:
            self.phase_published = self.t

    # ---- outputs ---------------------------------------------------------------------------
    @property
    def time_in_mode(self):
        return self.t - self.mode_entry

    @property
    def time_in_phase(self):
        return self.t - self.phase_entry if self.mode == DEORBIT else 0.0

    def powered(self):
        """{component: on} for the power-bus loads (LOAD_NAMES) and {command: on} for COMMANDS at the current state."""
        on = dict.fromkeys(LOAD_NAMES + COMMANDS, False)
        mode, phase = self.mode, self.phase
        if mode == END:
            return on
        nominal = (mode in (AWAITING, CONTACT, DEORBIT) or (mode in (IDLE, GRACE) and self.awake)
                   or (mode == MONITORING and self.in_contact))
        on["microprocessor_nominal"] = nominal
        on["microprocessor_quiescent"] = not nominal
        if mode == CONTACT or (mode == MONITORING and self.in_contact):
            on["uhf_rx"] = on["uhf_tx"] = on["downlink_enable"] = True
        if mode == AWAITING and self.p["listen_while_awaiting"]:
            on["uhf_rx"] = True
        if mode == MONITORING and self.in_contact:
            on["gps_receiver"] = on["gps_antenna"] = True
        if mode == DEORBIT:
            for name in ("horizon_sensor", "sun_sensor", "gyro", "gps_receiver", "gps_antenna", "data_recording"):
                on[name] = True
            on["propulsion"] = phase != ATTITUDE_DETERMINATION
            on["detumble_enable"] = phase == DETUMBLE
            on["slew_enable"] = phase == SLEW
            on["tracking_enable"] = on["burn_enable"] = phase == BURN
        return on

    # ---- state -----------------------------------------------------------------------------
    _STATE = ("t", "mode", "phase", "end_reason", "mode_entry", "phase_entry", "awake", "wake_end", "next_wake_k",
              "attempt", "detumble_timeouts", "slew_timeouts", "determination_timeouts", "safe_reason", "grace_end",
              "att_det_end", "att_det_waiting", "confirmed", "in_contact",
              "contact_seen", "last_beacon", "heartbeat_lost_at", "phase_published")

    def get_state(self):
        return {k: getattr(self, k) for k in self._STATE}

    def set_state(self, state):
        for k in self._STATE:
            setattr(self, k, state[k])
