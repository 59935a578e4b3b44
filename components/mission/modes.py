"""The mission manager's operating modes and de-orbit phases (thesis section 3.4, Figure 45),
as named integers: the FMU outputs `mode` and `phase` carry these values, the mission system's
schedule and the mission application read them by name."""
from enum import IntEnum


class MissionMode(IntEnum):
    IDLE = 1  # microprocessor quiescent, daily heartbeat checks
    GRACE = 2  # heartbeat lost: grace period
    AWAITING = 3  # grace period over: waiting for the final ground contact
    CONTACT = 4  # final contact: host status downlink, ground confirmation
    DEORBIT = 5  # attitude determination, detumble, slew, burn (DeorbitPhase)
    MONITORING = 6  # GPS beacon in ground contacts until the battery is empty or re-entry
    END = 7  # battery empty or re-entered: everything off


class DeorbitPhase(IntEnum):
    NONE = 0  # outside the de-orbit mode
    ATTITUDE_DETERMINATION = 1
    DETUMBLE = 2
    SLEW = 3
    BURN = 4


class EndReason(IntEnum):
    NONE = 0
    BATTERY = 1
    REENTERED = 2


MODE_NAMES = {MissionMode.IDLE: "idle", MissionMode.GRACE: "grace period",
              MissionMode.AWAITING: "awaiting final contact", MissionMode.CONTACT: "final contact",
              MissionMode.DEORBIT: "de-orbit", MissionMode.MONITORING: "monitoring", MissionMode.END: "end"}
PHASE_NAMES = {DeorbitPhase.NONE: "none", DeorbitPhase.ATTITUDE_DETERMINATION: "attitude determination",
               DeorbitPhase.DETUMBLE: "detumble", DeorbitPhase.SLEW: "slew", DeorbitPhase.BURN: "burn"}
MODE_TABLE = "; ".join(f"{int(k)} {v}" for k, v in MODE_NAMES.items())
PHASE_TABLE = "; ".join(f"{int(k)} {v}" for k, v in PHASE_NAMES.items())
