"""Route the torque command of the one enabled attitude controller to the thrusters.

The mission system runs three RCS controllers (detumble, slew, de-orbit tracking) against one
set of thruster pairs; the mission manager enables one at a time. An SSP input has a single
source, so the system needs this selector between the controllers and RcsThrusters. More than
one controller enabled at once is a wiring or mode-logic error, reported rather than summed.
"""
CONTROLLERS = ("detumble", "slew", "tracking")


def select_command(commands, enables):
    """The command (3 floats) of the enabled controller, zeros when none is enabled.

    commands: {controller: (x, y, z)}; enables: {controller: bool}, keys from CONTROLLERS."""
    on = [name for name in CONTROLLERS if enables.get(name)]
    if len(on) > 1:
        raise ValueError(f"more than one attitude controller enabled ({', '.join(on)}); "
                         "the mission manager must enable at most one of " + ", ".join(CONTROLLERS))
    if not on:
        return [0.0, 0.0, 0.0]
    return [float(x) for x in commands[on[0]]]
