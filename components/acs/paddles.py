"""Deployable solar paddles (ACS mode specification, mounted on the +Z face): a deploy command in, the state
"deployed" out.

Model: the deployment progresses while the deploy command is true (burn-wire release and
spring-driven hinge motion, lumped); the paddles are deployed once the commanded time reaches
deployment_time and stay deployed (latched; a dropped command before then pauses the
progress, it does not undo it). Default 60 s: within the specification's DPMD of 120 s, so the Deploy
Paddles mode sees them deployed before its delay runs out. Progress is advanced in step(h)
with the command held over the step, so `deployed` is a state (no direct feedthrough).
"""
import math


class Paddles:
    def __init__(self, deployment_time=60.0, deployed=False):
        deployment_time = float(deployment_time)
        if not (math.isfinite(deployment_time) and deployment_time >= 0):
            raise ValueError(f"parameter deployment_time = {deployment_time!r} s must be in [0, inf)")
        self.deployment_time = deployment_time
        self.progress = deployment_time if deployed else 0.0  # commanded time so far (s)
        self.deployed = bool(deployed)

    @property
    def fraction(self):
        if self.deployment_time == 0:
            return 1.0 if self.deployed else 0.0
        return min(1.0, self.progress / self.deployment_time)

    def step(self, deploy, h):
        if deploy and not self.deployed:
            self.progress += h
            if self.progress >= self.deployment_time - 1e-9:
                self.deployed = True

    def get_state(self):
        return {"progress": self.progress, "deployed": self.deployed}

    def set_state(self, state):
        self.progress = float(state["progress"])
        self.deployed = bool(state["deployed"])
