"""FMU `MissionManager` (instance `mission`): NEIGHBOR's operating modes (thesis section 3.4,
Figure 45), the de-orbit sub-phases, and what each mode powers (sections 3.5-3.6, Tables 5-7).

Wraps components.mission.manager.MissionManager (its docstring has the full mode logic and the
thesis ambiguities). do_step(t, h) evaluates the transitions from the inputs at the start of the
step (held over the step); internal timers (daily wake-up, grace period, attitude
determination) fire at their exact times inside the step and `next_event_time` announces the
next one. Every output is state: no output depends directly on an input. The model keeps the
time: the start time at initialization, t + h after do_step(t, h).
"""
from neighbor_fmu_support import NeighborSlave

from components.mission import manager as mm
from components.mission.modes import MODE_TABLE, PHASE_TABLE
from components.mission.power_bus import LOAD_NAMES, LOADS

D = mm.PARAMETER_DEFAULTS
PARAMETERS = (
    ("grace_period", "s", float, "Grace period after the heartbeat is found missing (>= 0); default 30 days"),
    ("wake_period", "s", float, "Period of the microprocessor's heartbeat checks in idle and grace period (> 0); "
                                "default 1 day"),
    ("wake_duration", "s", float, "Duration of each heartbeat check, in (0, wake_period); default 5 s"),
    ("wake_offset", "s", float, "Start of the first check window: windows start at wake_offset + k wake_period "
                                "(simulation time), in [0, wake_period)"),
    ("attitude_determination_duration", "s", float, "De-orbit phase 1 (attitude determination) duration (>= 0); "
                                                    "default 600 s"),
    ("battery_empty_soc", "1", float, "Battery empty (mission ends) when state_of_charge <= this, in [0, 1)"),
    ("initial_mode", None, int, f"Mode at the start time, 1..6 ({MODE_TABLE}); grace period and attitude "
                                "determination timers start at the start time"),
    ("initial_phase", None, int, f"De-orbit phase at the start time when initial_mode = 5, 1..4 ({PHASE_TABLE})"),
    ("listen_while_awaiting", None, bool, "UHF receiver on while awaiting the final contact (thesis text); false: "
                                          "radio on only during the contact (Appendix I)"),
    ("beacon_interval", "s", float, "Monitoring: beacon (GPS + UHF) only in a contact starting at least this long "
                                    "after the last contact used (>= 0; 0: every contact, Appendix I)"),
    ("detumble_timeout", "s", float, "A detumble not done after this long is retried, then the slew follows anyway "
                                     "(>= 0; 0: no timeout)"),
    ("slew_timeout", "s", float, "A slew not done after this long is retried, then the burn follows with the "
                                 "tracking controller holding the attitude (>= 0; 0: no timeout)"),
    ("phase_retries", None, int, "Retries of a timed-out detumble or slew before the mission moves on (>= 0)"),
)
APPENDED_PARAMETERS = (
    ("attitude_determination_timeout", "s", float,
     "After this long in attitude determination without attitude_valid the detumble starts anyway (it needs rates "
     "only; >= 0; 0: wait for a valid attitude)"),
    ("safe_without_attitude", None, bool,
     "Never start the slew or the burn without attitude_valid: a done detumble or slew waits for it, and at its "
     "timeout the de-orbit is abandoned for the safe state (monitoring, no thrust, safe_reason 1)"),
)
INPUTS = (
    ("heartbeat", None, bool, "Host spacecraft heartbeat present (HostSpacecraft.heartbeat)"),
    ("ground_contact", None, bool, "Ground station in contact (GroundStation.visible)"),
    ("ground_command", None, bool, "Ground's final confirmation to de-orbit (GroundStation.ground_command)"),
    ("detumble_done", None, bool, "Detumble controller finished (phase 2 -> 3)"),
    ("slew_done", None, bool, "Slew controller reached the burn attitude (phase 3 -> 4)"),
    ("budget_spent", None, bool, "Propellant budget spent: burn over (de-orbit -> monitoring)"),
    ("state_of_charge", "1", float, "Battery state of charge, 0..1 (Power)"),
    ("reentered", None, bool, "Spacecraft has re-entered (orbit FMU)"),
)
APPENDED_INPUTS = (
    ("attitude_valid", None, bool, "The attitude is known (AttitudeEstimator.attitude_valid): attitude determination "
                                   "lasts at least attitude_determination_duration and until this holds"),
)
# When the manager switches a load beyond the plain mode table (components.mission.manager).
LOAD_NOTES = {"microprocessor_quiescent": "; false when nominal or in end state",
              "propulsion": ", from detumble to the end of the burn"}
COMPONENT_TEXT = {
    **{load.name: f"Switch on: {load.description} (Table 5: {load.table5}){LOAD_NOTES.get(load.name, '')}"
       for load in LOADS},
    "detumble_enable": "Detumble controller enabled (de-orbit phase 2)",
    "slew_enable": "Slew controller enabled (de-orbit phase 3)",
    "tracking_enable": "Burn-attitude tracking controller enabled (de-orbit phase 4)",
    "burn_enable": "De-orbit burn thrust enabled (de-orbit phase 4)",
    "data_recording": "Status data stored (Table 7: during the de-orbit mode, all phases)",
    "downlink_enable": "UHF transmitting: host status in the final contact, GPS beacon and stored data in "
                       "monitoring-mode contacts",
}


class MissionManager(NeighborSlave):
    description = ("NEIGHBOR mission manager: idle with daily heartbeat checks, grace period, final ground "
                   "confirmation, de-orbit (attitude determination, detumble, slew, burn), monitoring, end; "
                   "powered components per mode")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, unit, kind, text in PARAMETERS:
            self.parameter(name, D[name], unit, text, kind)
        for name, unit, kind, text in INPUTS:
            self.input(name, mm.INPUT_DEFAULTS[name], unit, text, kind)
        self.output("mode", lambda: self.model.mode, None,
                    f"Operating mode ({MODE_TABLE}), decided from the inputs at the start of the last step", int)
        self.output("phase", lambda: self.model.phase, None, f"De-orbit sub-phase ({PHASE_TABLE}); 0 outside "
                    "the de-orbit mode", int)
        self.output("end_reason", lambda: self.model.end_reason, None,
                    "Why the mission ended: 0 not ended, 1 battery empty, 2 re-entered", int)
        for name in LOAD_NAMES + mm.COMMANDS:
            self.output(name, lambda name=name: self._powered()[name], None, COMPONENT_TEXT[name], bool)
        self.output("next_event_time", lambda: self.model.next_event_time, "s",
                    "Time of the next internal timed event (wake start/end, grace end, end of attitude "
                    "determination); 1e300 if none")
        self.output("detumble_timeouts", lambda: self.model.detumble_timeouts, None,
                    "Detumble phases that timed out so far (each retry counts)", int)
        self.output("slew_timeouts", lambda: self.model.slew_timeouts, None,
                    "Slew phases that timed out so far (each retry counts)", int)
        self.output("time_in_mode", lambda: self.model.time_in_mode, "s", "Time since the current mode was entered")
        self.output("time_in_phase", lambda: self.model.time_in_phase, "s",
                    "Time since the current de-orbit phase was entered (0 outside the de-orbit mode)")
        # appended after the first release's variables (their value references stay)
        for name, unit, kind, text in APPENDED_PARAMETERS:
            self.parameter(name, D[name], unit, text, kind)
        for name, unit, kind, text in APPENDED_INPUTS:
            self.input(name, mm.INPUT_DEFAULTS[name], unit, text, kind)
        self.output("determination_timeouts", lambda: self.model.determination_timeouts, None,
                    "Attitude determinations that ended at attitude_determination_timeout without a valid attitude",
                    int)
        self.output("safe_reason", lambda: self.model.safe_reason, None,
                    "Why the de-orbit was abandoned for the safe state: 0 it was not, 1 no valid attitude for the slew "
                    "or the burn", int)
        self.share_values(outputs=False)

    def _powered(self):
        model = self.model
        key = (self._model_generation, model.t, model.mode, model.phase, model.awake, model.in_contact)
        cache = self.__dict__.setdefault("_powered_cache", [None, None])
        if cache[0] != key:
            cache[0], cache[1] = key, model.powered()
        return cache[1]

    def build_model(self):
        params = {name: self.values[name] for name, _, _, _ in PARAMETERS + APPENDED_PARAMETERS}
        return mm.MissionManager(params, self.start_time)

    def do_step(self, current_time, step_size):
        inputs = {name: self.input_value(name) for name, _, _, _ in INPUTS + APPENDED_INPUTS}
        self.model.step(current_time, step_size, inputs)
        return True
