"""Fault detection for the RCS thrusters from the rate response: a thruster stuck off or on.

Flight software knows which thrusters it opened over each step and what each one's torque should
be (the nominal layout); the gyro tells what the body did. Within a window of `window` seconds
(default 1 s) the monitor follows, at every step k, the gyro's rate change against the one
Euler's equation predicts,

    E_k = (omega_k - omega_0) - sum_{j<k} J^-1 (L_j - omega_j x J omega_j) h_j,

where L_j is the nominal torque of the thrusters opened in step j (with the axial thrusters left
on in the burn). A constant gyro bias cancels. A thruster i with nominal rate signature
s_i = J^-1 L_i bends that curve in one of two ways: stuck off, E_k = -s_i c_ik, c_ik the seconds
it was opened up to k (it did not fire when opened); stuck on, E_k = +s_i (t_k - c_ik) (it fired
when closed). Each hypothesis is fitted with a free offset (the first sample's noise); its
weighted sum of squares uses the gyro's noise per sample plus a model error per opened thruster
(`model_error`, a fraction of its torque over the time it was open: force error, misalignment,
the inertia the software assumes). The time profile tells the two modes apart (a missing
negative torque and an extra positive one act at different times unless the controller never
rests).

A window names a candidate when its best hypothesis lowers the sum of squares by more than
`gate` (25: chi-square with one degree of freedom, about 6e-7 by chance); every hypothesis within
`gate` of the best belongs to it. Two can: when the controller never rests (a dead y+ thruster
reverses the y+ torque, the y+ command never stops) "y+ far stuck off" and "y- far stuck on" are
the same torque at the same times; no window tells them apart, and both are declared. Two of one
mode (x+1 or x+2 stuck off, whose torques differ only in the side torque a fast tumble's
gyroscopic term can hide), or more than two, name nothing: they are alternatives, and closing
both thrusters of a pair would leave its torque direction with none (a 475 km dispersed run with
x+1 dead and a 13.7 deg/s tumble closed x+1 and x+2 and never finished its detumble).
`confirmations` (2) windows in a row naming the same thrusters and modes declare the fault, so a
single disturbed window (a gyro bias jump) never does. Windows run only while every rate is below
`max_rate` (10 deg/s: in a faster tumble the gyroscopic term's inertia error hides a thruster; the
model error covers that term's share too) and no step is longer than a tenth of the window (the
attitude loop's steps; a long step starts the window over). One fault is
declared per run.

Operations choice (docs/models/mission.md, "Faults"): each declared thruster's latch valve is closed
(components.attitude.thruster_set.ThrusterSet.disable), which also stops a thruster stuck open,
and the flags are allocated over the others; the mission goes on.
"""
import math

import numpy as np

from ..core import checks

STUCK_OFF, STUCK_ON = 1, 2  # the modes a detection names


def declarable(group):
    """Whether a window's hypotheses within the gate of its best name a fault: one, or two as one
    thruster stuck off and another stuck on (the same torque at the same times). Two of one mode
    are alternatives the window cannot tell apart, and closing both could leave a torque direction
    with no thruster; more than two, nothing."""
    return len(group) == 1 or (len(group) == 2 and len({mode for _, mode in group}) == 2)


class ThrusterMonitor:
    """Windows of rate response against the thrusters opened (module docstring).

    torques: {thruster index: nominal torque (N.m, B)} of every thruster the software may open
    (RCS and axial); candidates: the indices that may fail (the RCS thrusters); inertia: 3x3
    (kg.m2) as the software knows it; rate_sigma, sample_time: the gyro's noise of one sample
    (rad/s) at that sample time (s), scaled to the step as the gyro's white rate noise."""

    def __init__(self, torques, candidates, inertia, rate_sigma, sample_time, window=1.0, confirmations=2,
                 gate=25.0, model_error=0.1, max_rate=math.radians(10.0)):
        J = np.array(inertia, dtype=float).reshape(3, 3)
        if not np.all(np.isfinite(J)) or np.any(np.linalg.eigvalsh(0.5 * (J + J.T)) <= 0.0):
            raise ValueError(f"inertia {J.tolist()} must be finite and positive definite (kg.m2)")
        J_inv = np.linalg.inv(J)
        self.index = sorted(int(i) for i in torques)  # column of each thruster in the open-time rows
        self.column = {i: k for k, i in enumerate(self.index)}
        self.signatures = np.array([J_inv @ np.asarray(torques[i], dtype=float) for i in self.index])
        self._torque_rows = [tuple(float(x) for x in torques[i]) for i in self.index]  # nominal, N.m
        self._J, self._J_inv = tuple(map(tuple, J.tolist())), tuple(map(tuple, J_inv.tolist()))
        self.candidates = sorted(int(i) for i in candidates)
        missing = [i for i in self.candidates if i not in self.column]
        if missing:
            raise ValueError(f"candidate thrusters {missing} have no torque")
        self.rate_sigma = checks.positive("rate_sigma", rate_sigma, "rad/s")
        self.sample_time = checks.positive("sample_time", sample_time, "s")
        self.window = checks.positive("window", window, "s")
        if isinstance(confirmations, bool) or int(confirmations) != confirmations or confirmations < 1:
            raise ValueError(f"confirmations = {confirmations!r} must be an integer >= 1")
        self.confirmations = int(confirmations)
        self.gate = checks.positive("gate", gate, "")
        self.model_error = float(model_error)
        if not (math.isfinite(self.model_error) and self.model_error >= 0.0):
            raise ValueError(f"model_error = {model_error!r} must be a finite fraction >= 0")
        self.max_rate = checks.positive("max_rate", max_rate, "rad/s")
        self.detected = None  # (((thruster index, STUCK_OFF or STUCK_ON), ...), time) once declared
        self._candidate, self._count = None, 0
        self._restart()

    def _restart(self):
        # per step of the window, in plain floats (the monitor runs at every 15 ms step)
        self._rates = []  # gyro rates at each step's start, the last at the window's end
        self._predicted = [(0.0, 0.0, 0.0)]  # predicted rate change up to each sample
        self._gyroscopic = [(0.0, 0.0, 0.0)]  # the gyroscopic term's share of it, in magnitude
        self._steps = []  # (columns of the thrusters opened, h) per step
        self._elapsed = 0.0
        self._h = None

    def step(self, t, omega, opened, h, excluded=()):
        """One step [t, t + h): `omega` the gyro's rates at t, `opened` the thrusters the software
        opens over the step, `excluded` the thrusters already disabled. Returns the detection the
        step declared, else None: (((index, mode), ...), time), two pairs when the response cannot
        tell them apart."""
        w0, w1, w2 = (float(x) for x in omega)
        largest = max(abs(w0), abs(w1), abs(w2))
        if not largest <= self.max_rate or h > 0.1 * self.window:  # also a NaN
            self._restart()
            return None
        declared = None
        self._rates.append((w0, w1, w2))
        if self._elapsed >= self.window - 1e-9:
            declared = None if self.detected is not None else self._evaluate(excluded, t)
            self._restart()
            self._rates.append((w0, w1, w2))
        columns = tuple(self.column[i] for i in opened if i in self.column)
        tx = ty = tz = 0.0
        for k in columns:
            x, y, z = self._torque_rows[k]
            tx, ty, tz = tx + x, ty + y, tz + z
        (j00, j01, j02), (j10, j11, j12), (j20, j21, j22) = self._J
        h0, h1, h2 = j00 * w0 + j01 * w1 + j02 * w2, j10 * w0 + j11 * w1 + j12 * w2, j20 * w0 + j21 * w1 + j22 * w2
        g0, g1, g2 = w1 * h2 - w2 * h1, w2 * h0 - w0 * h2, w0 * h1 - w1 * h0  # omega x J omega
        (i00, i01, i02), (i10, i11, i12), (i20, i21, i22) = self._J_inv
        n0, n1, n2 = tx - g0, ty - g1, tz - g2
        p0, p1, p2 = self._predicted[-1]
        self._predicted.append((p0 + (i00 * n0 + i01 * n1 + i02 * n2) * h, p1 + (i10 * n0 + i11 * n1 + i12 * n2) * h,
                                p2 + (i20 * n0 + i21 * n1 + i22 * n2) * h))
        q0, q1, q2 = self._gyroscopic[-1]
        self._gyroscopic.append((q0 + abs(i00 * g0 + i01 * g1 + i02 * g2) * h,
                                 q1 + abs(i10 * g0 + i11 * g1 + i12 * g2) * h,
                                 q2 + abs(i20 * g0 + i21 * g1 + i22 * g2) * h))
        self._steps.append((columns, h))
        self._elapsed += h
        self._h = h
        return declared

    def _evaluate(self, excluded, t):
        rates = np.array(self._rates)  # the samples at the window's steps, the last at its end
        n = len(rates)
        E = (rates - rates[0]) - np.array(self._predicted[:n])  # (n, 3)
        opened = np.zeros((n, len(self.index)))  # seconds each thruster was open up to each sample
        for k, (columns, h) in enumerate(self._steps[:n - 1], 1):
            opened[k, list(columns)] = h
        opened = np.cumsum(opened, axis=0)
        elapsed = np.concatenate(([0.0], np.cumsum([h for _, h in self._steps[:n - 1]])))
        sigma = self.rate_sigma * math.sqrt(self.sample_time / self._h)
        # variance per sample and axis: the gyro's noise, and each open thruster's model error
        variance = (sigma ** 2 + (self.model_error ** 2) * (opened ** 2) @ (self.signatures ** 2)
                    + (self.model_error * np.array(self._gyroscopic[:n])) ** 2)
        weights = 1.0 / variance

        def misfit(residual):  # weighted sum of squares about the best constant offset, per hypothesis
            mean = np.sum(weights * residual, axis=-2, keepdims=True) / np.sum(weights, axis=0)
            return np.sum(weights * (residual - mean) ** 2, axis=(-2, -1))

        null = float(misfit(E))
        hypotheses, curves = [], []
        for i in self.candidates:
            if i in excluded:
                continue
            k = self.column[i]
            hypotheses += [(i, STUCK_OFF), (i, STUCK_ON)]
            curves += [-opened[:, k], elapsed - opened[:, k]]
        hypothesis = None
        if hypotheses:
            curves = np.array(curves)  # (hypotheses, n)
            signatures = np.array([self.signatures[self.column[i]] for i, _ in hypotheses])
            fits = misfit(E[None, :, :] - curves[:, :, None] * signatures[:, None, :])
            best = float(np.min(fits))
            group = frozenset(hypotheses[k] for k in np.flatnonzero(fits < best + self.gate))
            if null - best > self.gate and declarable(group):
                hypothesis = group
        if hypothesis is not None and hypothesis == self._candidate:
            self._count += 1
        else:
            self._candidate, self._count = hypothesis, int(hypothesis is not None)
        if hypothesis is not None and self._count >= self.confirmations:
            self.detected = (tuple(sorted(hypothesis)), float(t))
            return self.detected
        return None

    def get_state(self):
        return {"rates": [list(w) for w in self._rates], "predicted": [list(p) for p in self._predicted],
                "gyroscopic": [list(g) for g in self._gyroscopic], "steps": [[list(c), h] for c, h in self._steps],
                "elapsed": self._elapsed, "h": self._h,
                "candidate": None if self._candidate is None else sorted(self._candidate), "count": self._count,
                "detected": None if self.detected is None else [list(self.detected[0]), self.detected[1]]}

    def set_state(self, state):
        self._rates = [tuple(float(x) for x in w) for w in state["rates"]]
        self._predicted = [tuple(float(x) for x in p) for p in state["predicted"]]
        self._gyroscopic = [tuple(float(x) for x in g) for g in state["gyroscopic"]]
        self._steps = [(tuple(int(k) for k in c), float(h)) for c, h in state["steps"]]
        self._elapsed = float(state["elapsed"])
        self._h = state["h"]
        self._candidate = None if state["candidate"] is None else frozenset(
            (int(i), int(mode)) for i, mode in state["candidate"])
        self._count = int(state["count"])
        d = state["detected"]
        self.detected = None if d is None else (tuple((int(i), int(mode)) for i, mode in d[0]), float(d[1]))
