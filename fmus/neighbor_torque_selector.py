"""FMU `TorqueSelector` (instance `selector`): passes the torque command of the enabled
attitude controller (detumble, slew or tracking) to the RCS thrusters.

Wraps components.attitude.command_selector.select_command. Direct feedthrough; no state.
"""
from neighbor_fmu_support import FRESH_FEEDTHROUGH, NeighborSlave

from components.attitude import command_selector


class _Stateless:
    def get_state(self):
        return None

    def set_state(self, state):
        pass


class TorqueSelector(NeighborSlave):
    description = ("Selects the torque command of the one enabled attitude controller (detumble, slew, "
                   "de-orbit tracking) for the RCS thrusters; two enabled at once is an error")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        deps: tuple = ()
        for name in command_selector.CONTROLLERS:
            command = self.input_array(f"torque_cmd_{name}_B", [0.0] * 3, "N.m",
                                       f"Torque command of the {name} controller")
            enable = self.input(f"{name}_enable", False, None, f"The {name} controller is the active one", bool)
            deps += command + (enable,)
        self.output_array("torque_cmd_B", 3, lambda: self.feedthrough(self._select), "N.m",
                          "Torque command of the enabled controller (zero when none is enabled)", depends_on=deps)
        self.share_values()
        self._outputs_at = self.shared_slice((("torque_cmd_B", 3),))

    def build_model(self):
        return _Stateless()

    def _select(self):
        names = command_selector.CONTROLLERS
        return command_selector.select_command({n: self.vector(f"torque_cmd_{n}_B", 3) for n in names},
                                               {n: self.input_value(f"{n}_enable") for n in names})

    def do_step(self, current_time, step_size):
        if not self.share_flags[FRESH_FEEDTHROUGH]:  # the command is a function of the inputs alone
            self.publish_after_step()
        return True

    def publish(self):
        # the getter's value (NeighborSlave.publish) in one write
        self.shared[self._outputs_at] = self._select()
        self.mark_published()
