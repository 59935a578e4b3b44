"""FMU `Paddles` (instance `paddles`): deployable solar paddles (ACS mode specification).

Wraps components.acs.paddles.Paddles: deployment progresses while `deploy` is true and latches
deployed after deployment_time. Outputs are states (no direct dependencies).
"""
from neighbor_fmu_support import NeighborSlave

from components.acs import paddles


class Paddles(NeighborSlave):
    description = "Deployable solar paddles: deploy command in, deployed after the deployment time (latched)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("deployment_time", 60.0, "s", "Commanded time to deploy, >= 0 (default 60 s < DPMD 120 s)")
        self.parameter("deployed0", False, None, "Paddles deployed at the start", bool)
        self.input("deploy", False, None, "Deployment commanded (the mode manager's paddle_deploy)", bool)
        self.output("paddles_deployed", lambda: self.model.deployed, None, "Paddles in state deployed", bool)
        self.output("deployment_fraction", lambda: self.model.fraction, "1",
                    "Commanded time over deployment_time, 0..1")

    def build_model(self):
        return paddles.Paddles(self.values["deployment_time"], self.values["deployed0"])

    def do_step(self, current_time, step_size):
        self.model.step(self.values["deploy"], step_size)
        return True
