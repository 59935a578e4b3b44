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
single disturbed window (a gyro bias jump) never does. These windows run only while every rate is
below `max_rate` (10 deg/s: in a faster tumble the gyroscopic term's inertia error, scaled this way,
hides a thruster; the model error covers that term's share too; above it, the fast windows below)
and no step is longer than a tenth of the window (the attitude loop's steps; a long step starts
the window over). One fault is declared per run.

Above `max_rate` the windows are of `fast_window` seconds (2 s) and fitted otherwise, so that a
thruster that spins the body up past 10 deg/s is still found: y+far stuck open from the detumble's
start gives 3.7 mN.m about y, more than the -y pair's 2.5 mN.m, and the body passes 10 deg/s in its
first seconds (without these windows it spun up to 943 deg/s and the estimator overflowed). The
residual is the same, but (1) the inertia error's share of the gyroscopic term is bounded per
axis rather than scaled from the nominal term: with each principal moment within `inertia_error`
(10 %, the dispersion's), (J_y - J_z)/J_x w_y w_z is off by at most inertia_error (J_y + J_z)/J_x
|w_y w_z|, which vanishes when the body spins about one axis (the spin a stuck thruster drives)
and is largest in a tumble about all three; and (2) the commands' effect is known only to a
common scale 1 + b, b fitted with the offsets under a prior of sigma `scale_error` (0.2: a mass
10 kg against the software's 12 kg is 0.2 alone). Without (2) a dispersed 10 kg body's
continuous firing in a fast tumble reads as a thruster. A stuck-open far thruster against its
axis' opposite pair needs b = -1.5 (3.7 against 2.5 mN.m): far outside the prior, so it is still
named, with the opposite far thruster stuck off, as a pair, and probed below 1 deg/s like any pair.

Operations choice (docs/models/mission.md, "Faults"): each declared thruster's latch valve is closed
(components.attitude.thruster_set.ThrusterSet.disable), which also stops a thruster stuck open,
and the flags are allocated over the others; the mission goes on.

A declaration of two (one stuck off, the other stuck on) closes a healthy valve with the faulty
one, and its torque direction then has one thruster left for good. So the monitor tests it later:
once every rate is below `probe_rate` (1 deg/s, past the detumble) it reopens the thruster named
stuck on and evaluates windows for that one hypothesis alone. Stuck on, it fires whenever it is
closed and is declared again in two windows (a second or two of one thruster's torque): its valve
is closed for good and the other's reopened, since one of the two was the fault. Not declared in
`probe_windows` (10) windows that could show it (closed for at least half the window), it stays
open, and the one named stuck off stays closed. Above `max_rate` the probe waits, as every window
does (the slew that follows the detumble turns at up to 16 deg/s). A probe that has not decided in
`probe_limit` (30) evaluated windows closes the valve again and leaves both closed: a stuck-on
thruster the controller keeps commanding (z+near stuck on with z-near closed is the -z command's
only thruster and part of +z's) fires for 30 of the monitor's windows at most.
"""
import math

import numpy as np

from ..core import checks

STUCK_OFF, STUCK_ON = 1, 2  # the modes a detection names
WAITING, TESTING, DONE = "waiting", "testing", "done"  # the probe of a declaration of two


def fraction(name, value):
    """`value` as a float, a finite fraction >= 0 (a model error), else a ValueError naming it."""
    x = float(value)
    if not (math.isfinite(x) and x >= 0.0):
        raise ValueError(f"{name} = {value!r} must be a finite fraction >= 0")
    return x


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
    (rad/s) at that sample time (s), scaled to the step as the gyro's white rate noise; the
    other arguments as in the module docstring."""

    def __init__(self, torques, candidates, inertia, rate_sigma, sample_time, window=1.0, confirmations=2,
                 gate=25.0, model_error=0.1, max_rate=math.radians(10.0), probe_rate=math.radians(1.0),
                 probe_windows=10, probe_limit=30, fast_window=2.0, inertia_error=0.1, scale_error=0.2):
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
        self.model_error = fraction("model_error", model_error)
        self.max_rate = checks.positive("max_rate", max_rate, "rad/s")
        self.probe_rate = checks.positive("probe_rate", probe_rate, "rad/s")
        if isinstance(probe_windows, bool) or int(probe_windows) != probe_windows or probe_windows < 1:
            raise ValueError(f"probe_windows = {probe_windows!r} must be an integer >= 1")
        self.probe_windows = int(probe_windows)
        if isinstance(probe_limit, bool) or int(probe_limit) != probe_limit or probe_limit < self.probe_windows:
            raise ValueError(f"probe_limit = {probe_limit!r} must be an integer >= probe_windows "
                             f"({self.probe_windows})")
        self.probe_limit = int(probe_limit)
        self.fast_window = checks.positive("fast_window", fast_window, "s")
        self.inertia_error = fraction("inertia_error", inertia_error)
        self.scale_error = checks.positive("scale_error", scale_error, "")
        self._J_array = J
        self.detected = None  # (((thruster index, STUCK_OFF or STUCK_ON), ...), time) once declared
        # the test of a declaration of two: {"on": index named stuck on, "off": the other, "state":
        # WAITING/TESTING/DONE, "windows": telling windows, "tested": windows evaluated, "resolved":
        # ((index, mode), time), or None while testing and when undecided}
        self.probe = None
        self._candidate, self._count = None, 0
        self._fast_candidate, self._fast_count = None, 0
        self._restart()
        self._restart_fast()

    def _restart_fast(self):
        # the windows above max_rate: gyro rates at each step's start (the last at the window's
        # end) and (columns of the thrusters opened, h) per step
        self._fast_rates = []
        self._fast_steps = []
        self._fast_elapsed = 0.0

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
        opens over the step, `excluded` the thrusters already disabled. Returns None, or what the
        valves should do before the step: (close, reopen, time), two tuples of thruster indices
        (a declaration closes one thruster, or two when the response cannot tell them apart; the
        probe of such a pair reopens one and then closes or keeps it)."""
        w0, w1, w2 = (float(x) for x in omega)
        largest = max(abs(w0), abs(w1), abs(w2))
        probe = self.probe
        if not largest == largest or h > 0.1 * self.window:  # a NaN or a long step
            self._restart()
            self._restart_fast()
            return None
        columns = tuple(self.column[i] for i in opened if i in self.column)
        if largest > self.max_rate:
            self._restart()
            if self.detected is None:
                return self._fast_step(t, (w0, w1, w2), columns, h, excluded)
            return None
        if self._fast_rates:
            self._restart_fast()
        if probe is not None and probe["state"] == WAITING and largest < self.probe_rate:
            # the window starts at the next step, the first with the reopened valve
            probe["state"], probe["windows"], probe["tested"] = TESTING, 0, 0
            self._candidate, self._count = None, 0
            self._restart()
            return (), (probe["on"],), float(t)
        action = None
        self._rates.append((w0, w1, w2))
        if self._elapsed >= self.window - 1e-9:
            if self.detected is None:
                action = self._declare(excluded, t)
            elif probe is not None and probe["state"] == TESTING:
                action = self._test(excluded, t)
            self._restart()
            self._rates.append((w0, w1, w2))
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
        return action

    def _fast_step(self, t, omega, columns, h, excluded):
        action = None
        self._fast_rates.append(omega)
        if self._fast_elapsed >= self.fast_window - 1e-9:
            hypothesis = self._evaluate_fast(excluded)
            if hypothesis is not None:
                action = self._declared(hypothesis, t)
            self._restart_fast()
            self._fast_rates.append(omega)
        self._fast_steps.append((columns, h))
        self._fast_elapsed += h
        return action

    def _evaluate_fast(self, excluded):
        """A window above max_rate (module docstring): the slow windows' rate response, with the
        inertia error's share of the gyroscopic term bounded per axis and the commands' effect
        known to a common scale."""
        rates = np.array(self._fast_rates)  # (n, 3), the last at the window's end
        n = len(rates)
        w = rates[:-1]
        steps = np.array([h for _, h in self._fast_steps[:n - 1]])
        opened = np.zeros((n - 1, len(self.index)))
        for k, (columns, h) in enumerate(self._fast_steps[:n - 1]):
            opened[k, list(columns)] = h

        def cumulative(x):  # per step -> per sample, zero at the window's start
            return np.concatenate((np.zeros((1,) + x.shape[1:]), np.cumsum(x, axis=0)))

        J, J_inv = self._J_array, np.array(self._J_inv)
        commanded = cumulative(opened @ self.signatures)  # J^-1 L h summed, (n, 3)
        gyroscopic = cumulative(np.cross(w, w @ J.T) @ J_inv.T * steps[:, None])
        E = (rates - rates[0]) - (commanded - gyroscopic)
        # each principal moment within inertia_error: (J_y - J_z)/J_x w_y w_z is off by at most
        # inertia_error (J_y + J_z)/J_x |w_y w_z|, and so on
        Jd = np.diag(J)
        after, next_ = [1, 2, 0], [2, 0, 1]
        pace = np.abs(w[:, after] * w[:, next_]) * (Jd[after] + Jd[next_]) / Jd
        sigma = self.rate_sigma * math.sqrt(self.sample_time / self._fast_steps[0][1])
        seconds = cumulative(opened)  # each thruster's seconds open up to each sample
        variance = (sigma ** 2 + self.model_error ** 2 * seconds ** 2 @ self.signatures ** 2
                    + (self.inertia_error * cumulative(pace * steps[:, None])) ** 2)
        weights = 1.0 / variance
        total = np.sum(weights, axis=0)

        def centred(x):  # about each axis' weighted mean (the free offsets)
            return x - np.sum(weights * x, axis=-2, keepdims=True) / total

        # the commands' true effect is (1 + b) times the one predicted (the mass, inertia and force
        # the software assumes), b with a prior of sigma scale_error: fitted with the offsets
        C = centred(commanded)
        prior = np.sum(weights * C ** 2) + 1.0 / self.scale_error ** 2

        def misfit(residual):
            R = centred(residual)
            return np.sum(weights * R ** 2, axis=(-2, -1)) - np.sum(weights * R * C, axis=(-2, -1)) ** 2 / prior

        null = float(misfit(E))
        return self._confirmed(self._named(null, misfit, E, excluded, self.candidates, (STUCK_OFF, STUCK_ON), seconds,
                                           cumulative(steps)), fast=True)

    def _confirmed(self, hypothesis, fast=False):
        """`hypothesis` once `confirmations` windows in a row (the slow and the fast ones each on
        their own) have named it, else None."""
        candidate, count = (self._fast_candidate, self._fast_count) if fast else (self._candidate, self._count)
        count = count + 1 if hypothesis is not None and hypothesis == candidate else int(hypothesis is not None)
        if fast:
            self._fast_candidate, self._fast_count = hypothesis, count
        else:
            self._candidate, self._count = hypothesis, count
        return hypothesis if hypothesis is not None and count >= self.confirmations else None

    def _named(self, null, misfit, E, excluded, candidates, modes, seconds, elapsed):
        """The hypotheses a window names (a frozenset of (index, mode)), or None: those within the
        gate of the best, when the best beats no fault by more than the gate and they are declarable.
        Each of `candidates` not `excluded`, in each of `modes`, bends E by its signature times a
        curve: stuck off, minus the seconds it was open (`seconds`, per sample and thruster); stuck
        on, the seconds it was closed (`elapsed` less those)."""
        hypotheses, curves = [], []
        for i in candidates:
            if i in excluded:
                continue
            k = self.column[i]
            for mode in modes:
                hypotheses.append((i, mode))
                curves.append(-seconds[:, k] if mode == STUCK_OFF else elapsed - seconds[:, k])
        if not hypotheses:
            return None
        curves = np.array(curves)  # (hypotheses, n)
        signatures = np.array([self.signatures[self.column[i]] for i, _ in hypotheses])
        fits = misfit(E[None, :, :] - curves[:, :, None] * signatures[:, None, :])
        best = float(np.min(fits))
        group = frozenset(hypotheses[k] for k in np.flatnonzero(fits < best + self.gate))
        return group if null - best > self.gate and declarable(group) else None

    def _declare(self, excluded, t):
        hypothesis = self._evaluate(excluded, t, self.candidates, (STUCK_OFF, STUCK_ON))
        if hypothesis is None:
            return None
        return self._declared(hypothesis, t)

    def _declared(self, hypothesis, t):
        self.detected = (tuple(sorted(hypothesis)), float(t))
        if len(hypothesis) == 2:
            (on,) = (i for i, mode in hypothesis if mode == STUCK_ON)
            (off,) = (i for i, mode in hypothesis if mode == STUCK_OFF)
            self.probe = {"on": on, "off": off, "state": WAITING, "windows": 0, "tested": 0, "resolved": None}
        return tuple(sorted(i for i, _ in hypothesis)), (), float(t)

    def _test(self, excluded, t):
        probe = self.probe
        on, off = probe["on"], probe["off"]
        closed = self._elapsed - sum(h for columns, h in self._steps if self.column[on] in columns)
        if self._evaluate(excluded, t, (on,), (STUCK_ON,)) is not None:
            probe["state"], probe["resolved"] = DONE, ((on, STUCK_ON), float(t))
            return (on,), (off,), float(t)
        probe["tested"] += 1
        if closed >= 0.5 * self._elapsed:  # a window in which a stuck-on valve would have shown
            probe["windows"] += 1
        if probe["windows"] >= self.probe_windows and self._count == 0:
            probe["state"], probe["resolved"] = DONE, ((off, STUCK_OFF), float(t))
        elif probe["tested"] >= self.probe_limit:
            probe["state"] = DONE  # undecided: both closed again
            return (on,), (), float(t)
        return None

    def _evaluate(self, excluded, t, candidates, modes):
        """The window's declaration among `candidates` in `modes` once confirmed, else None."""
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
        return self._confirmed(self._named(null, misfit, E, excluded, candidates, modes, opened, elapsed))

    def get_state(self):
        return {"rates": [list(w) for w in self._rates], "predicted": [list(p) for p in self._predicted],
                "gyroscopic": [list(g) for g in self._gyroscopic], "steps": [[list(c), h] for c, h in self._steps],
                "elapsed": self._elapsed, "h": self._h,
                "candidate": None if self._candidate is None else sorted(self._candidate), "count": self._count,
                "fast_rates": [list(w) for w in self._fast_rates],
                "fast_steps": [[list(c), h] for c, h in self._fast_steps], "fast_elapsed": self._fast_elapsed,
                "fast_candidate": None if self._fast_candidate is None else sorted(self._fast_candidate),
                "fast_count": self._fast_count,
                "detected": None if self.detected is None else [list(self.detected[0]), self.detected[1]],
                "probe": None if self.probe is None else {
                    **self.probe, "resolved": None if self.probe["resolved"] is None else
                    [list(self.probe["resolved"][0]), self.probe["resolved"][1]]}}

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
        # states saved before the windows above max_rate carry none
        self._fast_rates = [tuple(float(x) for x in w) for w in state.get("fast_rates", [])]
        self._fast_steps = [(tuple(int(k) for k in c), float(h)) for c, h in state.get("fast_steps", [])]
        self._fast_elapsed = float(state.get("fast_elapsed", 0.0))
        fast = state.get("fast_candidate")
        self._fast_candidate = None if fast is None else frozenset((int(i), int(mode)) for i, mode in fast)
        self._fast_count = int(state.get("fast_count", 0))
        d = state["detected"]
        self.detected = None if d is None else (tuple((int(i), int(mode)) for i, mode in d[0]), float(d[1]))
        probe = state.get("probe")  # states saved before the probe carry none
        if probe is None:
            self.probe = None
        else:
            resolved = probe["resolved"]
            self.probe = {"on": int(probe["on"]), "off": int(probe["off"]), "state": str(probe["state"]),
                          "windows": int(probe["windows"]), "tested": int(probe["tested"]),
                          "resolved": None if resolved is None else ((int(resolved[0][0]), int(resolved[0][1])),
                                                                     float(resolved[1]))}
