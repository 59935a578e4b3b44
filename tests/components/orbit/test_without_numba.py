"""numba only makes the kernels faster: with it switched off (NEIGHBOR_COSIM_NUMBA=0, the path
a host without numba takes) the atmospheres, the Cowell orbit and the orbit-averaged model give
the same results to 1e-12."""
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


def test_describe_names_the_path():
    assert ("numba" in jit.describe()) and ("compiled" in jit.describe()) == jit.ENABLED
