"""numba only makes the kernels faster: with it switched off (NEIGHBOR_COSIM_NUMBA=0, the path
a host without numba takes) the atmospheres, the Cowell orbit, the orbit-averaged model, the
attitude filter's matrix arithmetic, the estimator's compiled step and the attitude models'
steps on shared arrays (rigid body, thruster pairs, detumble and tracking laws) give the same results to 1e-12,
and the attitude models' (the kernels declared plain_first) the same bits."""
import json
import os
import subprocess
import sys

import numpy as np

from components.core import jit

CASES = r"""
import json, math
import numpy as np
from components.core import jit
from components.environment import atmosphere, space_weather
from components.orbit import averaged, cowell
from components.sensing import mekf, triad
from components.core import rotations

out = {"numba": jit.ENABLED}
sw = space_weather.SpaceWeather.from_file()
r = np.array([4.1e6, -3.2e6, 4.4e6])
jd = 2459950.31
for name in ("exponential", "harris_priester", "jacchia_roberts"):
    m = atmosphere.make_density_model(name, space_weather=sw, inclination=math.radians(51.6))
    out[name] = [m.density(r * k, jd + 0.1 * k) for k in (1.0, 1.02, 1.05)]
    orbit = cowell.CowellOrbit(density_model=m, sma0=6378136.3 + 400e3, inc0=math.radians(51.6), t0=0.0)
    orbit.set_inputs([0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], True, 12.0)
    orbit.advance_to(1800.0)
    orbit.set_inputs([0.1, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0], True, 12.0)
    orbit.advance_to(2400.0)
    out["cowell_" + name] = [float(x) for x in orbit.y]
    lifetime = averaged.OrbitAveraged(m, sma0=6378136.3 + 380e3)
    lifetime.advance_to(2 * 86400.0)
    out["averaged_" + name] = [float(x) for x in lifetime.y]
filt = mekf.AttitudeMEKF()
filt.initialize((0.1, 0.2, 0.3, 0.9), 0.02, bias=(1e-3, -2e-3, 3e-3), sigma_bias=1e-3)
q_true, nis = rotations.normalized((0.12, 0.18, 0.31, 0.89)), []
for k in range(40):
    filt.propagate([0.01, -0.02, 0.015], 0.1)
    A = rotations.attitude_matrix(q_true)
    for r in ((1.0, 0.0, 0.0), (0.3, 0.9, -0.2)):
        r = rotations.normalized(r)
        b = [A[i][0] * r[0] + A[i][1] * r[1] + A[i][2] * r[2] + 1e-3 * math.sin(7 * k + i) for i in range(3)]
        nis.append(filt.update(b, r, 2e-3)[0])
out["mekf"] = list(filt.q) + filt.bias.tolist() + np.diag(filt.P).tolist() + nis + [filt.attitude_nees(q_true)]
est = mekf.AttitudeEstimator(inertia=np.diag([0.05, 0.1, 0.1]), accel_sigma=5e-4)
u, y, outputs = np.zeros(mekf.U_SIZE), np.zeros(mekf.Y_SIZE), []
u[mekf.U_R_BN:mekf.U_R_BN + 3], u[mekf.U_R_SN:mekf.U_R_SN + 3] = (6.8e6, 0.0, 0.0), (0.0, 1.5e11, 0.0)
u[mekf.U_NADIR_VALID] = u[mekf.U_SUN_VALID] = 1.0
q, w = rotations.normalized((0.1, 0.2, 0.3, 0.9)), (0.05, 0.01, -0.02)
sun_N = rotations.normalized((-6.8e6, 1.5e11, 0.0))
for k in range(300):  # 4.5 s of a slow tumble: the first fix, vector updates every 0.5 s, the steps between
    q = triad.propagate(q, w, 0.015)
    A = rotations.attitude_matrix(q)
    for at, r in ((mekf.U_NADIR, (-1.0, 0.0, 0.0)), (mekf.U_SUN, sun_N)):
        if k % 33 == 0:
            u[at:at + 3] = [A[i][0] * r[0] + A[i][1] * r[1] + A[i][2] * r[2] + 1e-3 * math.cos(k + i) for i in range(3)]
    u[mekf.U_RATE:mekf.U_RATE + 3] = (w[0] + 1e-3 + 5e-4 * math.sin(k), w[1] - 2e-3, w[2] + 5e-4 * math.cos(k))
    u[mekf.U_TORQUE:mekf.U_TORQUE + 3] = (1e-4, 0.0, -1e-4)
    u[mekf.U_Q_TRUE:mekf.U_Q_TRUE + 4], u[mekf.U_RATE_TRUE:mekf.U_RATE_TRUE + 3] = q, w
    outputs.append(est.step_packed(u, 0.015, True, y))
    outputs.extend(y.tolist())
out["estimator"] = outputs + [est.consistency.total]
# the attitude models' steps on the arrays an FMU shares with the runtime
from components.attitude import detumble, rigid_body, thrusters
J = [[0.1, 0.002, 0.0], [0.002, 0.12, 0.0], [0.0, 0.0, 0.15]]
for integrator in ("euler", "rk4"):
    body = rigid_body.RigidBody(J, (0.1, 0.2, 0.3, 0.9), (0.17, -0.1, 0.05), integrator)
    pairs, law = thrusters.ThrusterPairs(), detumble.DetumbleController([100.0] * 3, [1.0] * 3, settle_time=0.03)
    values, outputs = np.zeros(90), []
    for k in range(200):  # inputs 0:9 body, 20:27 law, 40:43 pairs; outputs 30:37 law, 44:58 pairs, 60:82 body
        values[20:26] = body.omega + body.omega_dot
        values[26] = float(k % 50 != 7)
        law.step_into(values, np.arange(20, 27), np.arange(30, 37), 0.015)
        values[40:43] = values[30:33]
        pairs.step_into(values, np.arange(40, 43), np.arange(44, 58), 0.015)
        values[0:3], values[3:6], values[6:9] = values[44:47], (1e-4, 0.0, -1e-4), (0.0, 1e-3, 0.0)
        if k % 2:
            body.step_from(values, np.arange(9), 0.015)
            body.publish_into(values, np.arange(60, 82))
        else:  # the FMU's step: the two in one compiled call
            assert body.step_and_publish(values, np.arange(9), np.arange(60, 82), 0.015)
        outputs.extend(values.tolist())
    out["attitude_" + integrator] = outputs
# the de-orbit tracking law's step and publish (its boundary layer's and pointing error's hypot:
# math.hypot in plain Python, cpython_math's compiled)
from components.attitude import deorbit_tracking
law = deorbit_tracking.DeorbitTrackingController(J, knowledge_sigmas=3.0, impulse_bits=1.0, rate_sigma=1e-4)
values, outputs = np.zeros(40), []
inputs, published = np.arange(18), np.arange(20, 39)
for k in range(200):
    values[0:4] = rotations.normalized((0.1 + 1e-3 * math.sin(k), 0.2, 0.3, 0.9))
    values[4:7], values[7] = (1e-3 * math.cos(k), 2e-3, -1e-3), float(k % 50 != 7)
    values[8:12], values[12:15] = rotations.normalized((0.1, 0.2 + 0.01 * (k // 30), 0.3, 0.9)), (0.0, 1.1e-3, 0.0)
    values[15:18] = (1e-3 * (1 + math.sin(k)), 2e-3, 5e-4 * (1 + math.cos(k)))
    outputs.append(deorbit_tracking.tracking_into(law.constants, law.x, values, inputs, published, 0.0, False, True))
    outputs.append(deorbit_tracking.tracking_into(law.constants, law.x, values, inputs, published, 0.015, True, True))
    outputs.extend(values.tolist())
out["tracking"] = outputs
print(json.dumps(out))
"""


def run(numba_on):
    env = dict(os.environ, NEIGHBOR_COSIM_NUMBA="1" if numba_on else "0")
    proc = subprocess.run([sys.executable, "-c", CASES], capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_plain_python_kernels_equal_the_compiled_ones():
    compiled, plain = run(True), run(False)
    assert compiled.pop("numba") is jit.ENABLED and plain.pop("numba") is False
    assert compiled.keys() == plain.keys()
    for key in compiled:
        np.testing.assert_allclose(plain[key], compiled[key], rtol=1e-12, atol=0, err_msg=key)
    assert compiled["cowell_exponential"] != compiled["cowell_jacchia_roberts"]  # the cases differ
    # the attitude models' kernels are declared plain_first: a short run takes them as plain Python
    # before numba is loaded (components.core.jit), which must not change a bit
    for key in ("attitude_euler", "attitude_rk4", "tracking"):
        assert plain[key] == compiled[key], key


def test_describe_names_the_path():
    assert ("numba" in jit.describe()) and ("compiled" in jit.describe()) == jit.ENABLED
