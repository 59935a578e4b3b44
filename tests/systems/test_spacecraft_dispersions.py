"""Spacecraft dispersions of campaigns (issue 58): an inertia tensor that stays a real body, an
attitude and a rate uniform on the sphere, a direction uniform on a cone; each run's draws from
its own seed; bad tables refused naming the key. The distributions are checked with scipy's
Kolmogorov-Smirnov test on a few thousand draws."""
import math

import numpy as np
import pytest
from scipy import stats

from components.core import rotations
from system_ssp import SSPError, System
from system_ssp.tools.campaign import load_spec
from system_ssp.tools.campaign.runner import check_against_system
from system_ssp.tools.campaign.spacecraft import spacecraft_dispersion
from system_ssp.tools.campaign.worker import run_one

NOMINAL = [[0.05, 0.002, 0.0], [0.002, 0.1, 0.0], [0.0, 0.0, 0.13]]
N = 4000


def _draws(table, name="d.x"):
    d = spacecraft_dispersion("spec.toml", name, table)
    rng = np.random.default_rng(1)
    return d, [d.draw(rng) for _ in range(N)]


def test_inertia_stays_a_real_body_near_the_nominal_one():
    d, draws = _draws({"distribution": "inertia", "nominal": NOMINAL, "moments": 0.1, "axes": 0.05},
                      "dynamics.inertia_B")
    assert d.columns[0] == "dynamics.inertia_B[1,1]" and len(d.columns) == 9
    nominal_moments, nominal_axes = np.linalg.eigh(NOMINAL)
    ratios, angles = [], []
    for v in draws:
        J = np.array([[v[f"dynamics.inertia_B[{i},{j}]"] for j in (1, 2, 3)] for i in (1, 2, 3)])
        assert np.array_equal(J, J.T)
        m, axes = np.linalg.eigh(J)
        assert m[0] > 0 and m[2] <= m[0] + m[1]  # positive definite, and a body's (triangle inequality)
        ratios.append(m / nominal_moments)
        # the principal axes turned by at most 0.05 rad (each axis up to its sign)
        angles.append(max(math.acos(min(1.0, abs(axes[:, k] @ nominal_axes[:, k]))) for k in range(3)))
    ratios = np.array(ratios)
    assert ratios.min() >= 0.9 - 1e-9 and ratios.max() <= 1.1 + 1e-9
    for k in range(3):  # each moment's factor uniform in [0.9, 1.1]
        assert stats.kstest(ratios[:, k], stats.uniform(0.9, 0.2).cdf).pvalue > 1e-3
    assert max(angles) <= 0.05 + 1e-9 and np.mean(angles) > 0.02


def test_attitudes_and_rates_uniform_on_the_sphere():
    for table in ({"distribution": "attitude"}, {"distribution": "attitude", "low": 0.0, "high": math.pi}):
        d, draws = _draws(table, "dynamics.q0")
        q = np.array([[v[f"dynamics.q0[{i}]"] for i in (1, 2, 3, 4)] for v in draws])
        assert np.allclose(np.linalg.norm(q, axis=1), 1.0) and np.all(q[:, 3] >= 0.0)
        x = np.array([np.array(rotations.attitude_matrix(tuple(row)))[:, 0] for row in q])
        # the body x axis in N: uniform on the sphere, so each component uniform in [-1, 1]
        for k in range(3):
            assert stats.kstest(x[:, k], stats.uniform(-1.0, 2.0).cdf).pvalue > 1e-3, table
    d, draws = _draws({"distribution": "attitude", "nominal": [0.0, 0.0, 0.7071067811865476, 0.7071067811865476],
                       "low": 0.1, "high": 0.2, "form": "mrp"}, "dynamics.sigma0")
    nominal = (0.0, 0.0, 0.7071067811865476, 0.7071067811865476)
    for v in draws[:200]:
        s = np.array([v[f"dynamics.sigma0[{i}]"] for i in (1, 2, 3)])
        q = np.concatenate([2 * s, [1 - s @ s]]) / (1 + s @ s)  # the MRP's quaternion
        turn = rotations.circle_cross(tuple(q), rotations.conjugate(nominal))
        angle = 2 * math.acos(min(1.0, abs(turn[3])))
        assert 0.1 - 1e-9 <= angle <= 0.2 + 1e-9
    d, draws = _draws({"distribution": "rate", "low": 0.05, "high": 0.2}, "dynamics.omega0")
    w = np.array([[v[f"dynamics.omega0[{i}]"] for i in (1, 2, 3)] for v in draws])
    size = np.linalg.norm(w, axis=1)
    assert size.min() >= 0.05 and size.max() <= 0.2
    assert stats.kstest(size, stats.uniform(0.05, 0.15).cdf).pvalue > 1e-3
    for k in range(3):
        assert stats.kstest(w[:, k] / size, stats.uniform(-1.0, 2.0).cdf).pvalue > 1e-3


def test_thruster_directions_uniform_on_their_cone():
    d, draws = _draws({"distribution": "cone", "half_angle": math.radians(1.0), "count": 16,
                       "parameters": ["thrusters.misalignment_1[{i}]", "thrusters.misalignment_2[{i}]"]}, "tilts")
    assert d.columns[:4] == ("thrusters.misalignment_1[1]", "thrusters.misalignment_2[1]",
                             "thrusters.misalignment_1[2]", "thrusters.misalignment_2[2]") and len(d.columns) == 32
    theta = np.array([math.hypot(v["thrusters.misalignment_1[3]"], v["thrusters.misalignment_2[3]"]) for v in draws])
    assert theta.max() <= math.radians(1.0)
    # uniform on the spherical cap: cos(theta) uniform in [cos(1 deg), 1]
    c = math.cos(math.radians(1.0))
    assert stats.kstest(np.cos(theta), stats.uniform(c, 1 - c).cdf).pvalue > 1e-3


@pytest.mark.parametrize("name, table, pattern", [
    ("dynamics.inertia_B", {"distribution": "inertia", "nominal": [[1, 0, 0], [0, 1, 0], [1, 0, 1]], "moments": 0.1,
                            "axes": 0.0}, r"expected a symmetric 3x3 matrix"),
    ("dynamics.inertia_B", {"distribution": "inertia", "nominal": [[1, 0, 0], [0, 1, 0], [0, 0, 3]], "moments": 0.1,
                            "axes": 0.0}, r"principal moments 1, 1, 3 are not a real body's"),
    ("dynamics.inertia_B", {"distribution": "inertia", "nominal": NOMINAL, "moments": 0.1}, r"missing axes"),
    ("dynamics.inertia_B", {"distribution": "inertia", "nominal": NOMINAL, "moments": 0.7, "axes": 0.0},
     r"moments = 0.7: expected a number in \[0, 0.5\]"),
    ("dynamics.q0[1]", {"distribution": "attitude"}, r"names the vector parameter without an index"),
    ("dynamics.q0", {"distribution": "attitude", "high": 4.0}, r"high = 4.0: expected a number in \[0, 3.14159\]"),
    ("dynamics.q0", {"distribution": "attitude", "nominal": [0, 0, 0, 2]}, r"expected a unit quaternion"),
    ("dynamics.omega0", {"distribution": "rate", "low": 0.3, "high": 0.2}, r"low > high"),
    ("tilts", {"distribution": "cone", "half_angle": 0.1, "parameters": ["a.b[{i}]", "a.c"], "count": 2},
     r"count = 2 needs \{i\} in both parameter names"),
])
def test_bad_spacecraft_dispersions(name, table, pattern):
    with pytest.raises(SSPError, match=pattern):
        spacecraft_dispersion("spec.toml", name, table)


SPEC = """
[campaign]
system = "{system}"
parameter_sets = ["parameters/detumble_case1.ssv"]
runs = 3
seed = 9
stop_time = 2.0
[parameters]
"dynamics.inertia_from_box" = false
[dispersions."dynamics.inertia_B"]
distribution = "inertia"
nominal = [[0.05, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.13]]
moments = 0.1
axes = 0.1
[dispersions."dynamics.q0"]
distribution = "attitude"
[dispersions."dynamics.omega0"]
distribution = "rate"
low = 0.0
high = 0.2
[metrics]
q4 = "final:dynamics.q_BN[4]"
h = "final:dynamics.H_B[1]"
"""


def test_a_campaign_draws_them_per_run_and_the_body_gets_them(ssp_paths, tmp_path):
    path = tmp_path / "spec.toml"
    path.write_text(SPEC.format(system=ssp_paths["detumble"]))
    spec = load_spec(path)
    check_against_system(spec)
    assert [spec.inputs(i) for i in (2, 0, 1)] == [spec.inputs(i) for i in (2, 0, 1)]
    row = run_one(spec, 1)
    assert row["status"] in ("ok", "incomplete"), row["error"]
    _, values = spec.inputs(1)
    assert row["dynamics.inertia_B[2,3]"] == values["dynamics.inertia_B[2,3]"] != 0.0
    # the body's momentum at the start is its drawn inertia times its drawn rate
    J = np.array([[values[f"dynamics.inertia_B[{i},{j}]"] for j in (1, 2, 3)] for i in (1, 2, 3)])
    w = np.array([values[f"dynamics.omega0[{i}]"] for i in (1, 2, 3)])
    with System(spec.system) as system:
        r = system.run(stop_time=0.1, parameter_sets=spec.parameter_sets, parameters=spec.overrides(values),
                       outputs=["dynamics.H_B[1]", "dynamics.H_B[2]", "dynamics.H_B[3]"])
    assert [r.data[f"dynamics.H_B[{i}]"][0] for i in (1, 2, 3)] == pytest.approx(J @ w, rel=1e-12)
    path.write_text(SPEC.format(system=ssp_paths["detumble"]).replace('"dynamics.q0"', '"dynamics.qq0"'))
    with pytest.raises(SSPError, match=r"dispersions.dynamics.qq0: parameter 'dynamics.qq0\[1\]'"):
        check_against_system(load_spec(path))
