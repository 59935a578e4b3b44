"""Spacecraft dispersions: draws that set several parameters together and keep them physical.

- `inertia`: an inertia tensor about a nominal one. Its principal moments each scaled by a factor
  uniform in 1 +- `moments`, redrawn until they satisfy the triangle inequalities (a real body:
  each moment at most the sum of the other two), its principal axes turned by an angle uniform in
  [0, `axes`] rad about an axis uniform on the sphere. The tensor is symmetric positive definite
  by construction; it sets name[i,j] for i, j in 1..3 (RigidBody's inertia_B).
- `attitude`: an attitude uniform over those within [`low`, `high`] rad of the nominal one
  (default 0 and pi: uniform over every attitude, the Haar measure: the axis of the turn uniform
  on the sphere, its angle with density 1 - cos); name[1..4] a quaternion (scalar last, q_BN as
  the models take it) or, with form = "mrp", name[1..3] its MRPs (scalar part >= 0: |sigma| <= 1).
- `rate`: a vector of magnitude uniform in [`low`, `high`] along a direction uniform on the
  sphere: name[1..3] (an initial body rate, omega0).
- `cone`: a direction within `half_angle` of its nominal one, uniform over the spherical cap,
  as two perpendicular tilts (the two parameters of `parameters`, e.g. a thruster's
  misalignment_1 and misalignment_2); with `count = n` and `{i}` in the names, n independent
  cones (i = 1..n).
Each draws from the run's own generator, so a run draws the same values on any worker."""
from dataclasses import dataclass
import math
from typing import Any, Dict, List, Mapping, Tuple

import numpy as np

from ...errors import SSPError

KINDS = {"inertia": ("nominal", "moments", "axes"), "attitude": (), "rate": ("low", "high"),
         "cone": ("half_angle", "parameters")}
OPTIONAL = {"inertia": (), "attitude": ("nominal", "low", "high", "form"), "rate": (),
            "cone": ("count",)}


def _axis(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The rotation matrix turning vectors by `angle` about `axis` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _then(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The attitude q turned by p: the quaternion product p (x) q, scalar last, the models'
    convention (components.core.rotations.circle_cross; the tools import no model)."""
    return np.concatenate([p[3] * q[:3] + q[3] * p[:3] - np.cross(p[:3], q[:3]), [p[3] * q[3] - p[:3] @ q[:3]]])


@dataclass(frozen=True)
class SpacecraftDispersion:
    """One compound dispersion of a campaign spec (see the module's text)."""
    name: str
    kind: str
    args: Mapping[str, Any]

    @property
    def also(self) -> Tuple[str, ...]:
        return ()

    @property
    def columns(self) -> Tuple[str, ...]:
        a = self.args
        if self.kind == "inertia":
            return tuple(f"{self.name}[{i},{j}]" for i in (1, 2, 3) for j in (1, 2, 3))
        if self.kind == "attitude":
            return tuple(f"{self.name}[{i}]" for i in range(1, 4 if a.get("form") == "mrp" else 5))
        if self.kind == "rate":
            return tuple(f"{self.name}[{i}]" for i in (1, 2, 3))
        count = int(a.get("count", 1))
        names = list(a["parameters"])
        return tuple(n.replace("{i}", str(i)) for i in range(1, count + 1) for n in names)

    def draw(self, rng: np.random.Generator) -> Dict[str, float]:
        a = self.args
        if self.kind == "inertia":
            values = self._inertia(rng).ravel()
        elif self.kind == "attitude":
            values = self._attitude(rng)
        elif self.kind == "rate":
            values = _axis(rng) * rng.uniform(a["low"], a["high"])
        else:
            out: List[float] = []
            for _ in range(int(a.get("count", 1))):
                cos_theta = 1.0 - rng.uniform() * (1.0 - math.cos(a["half_angle"]))  # uniform on the cap
                theta, phi = math.acos(cos_theta), rng.uniform(0.0, 2.0 * math.pi)
                out += [theta * math.cos(phi), theta * math.sin(phi)]
            values = np.array(out)
        return {name: float(v) for name, v in zip(self.columns, values)}

    def _inertia(self, rng: np.random.Generator) -> np.ndarray:
        a = self.args
        moments, axes = np.linalg.eigh(np.asarray(a["nominal"], dtype=float))
        for _ in range(10000):
            m = moments * (1.0 + rng.uniform(-a["moments"], a["moments"], size=3))
            if all(m[k] <= m[(k + 1) % 3] + m[(k + 2) % 3] for k in range(3)):
                break
        else:  # pragma: no cover - the spec check makes the nominal body a real one
            raise SSPError(f"dispersion {self.name}: no real body within moments = {a['moments']:g}")
        turn = _rotation(_axis(rng), rng.uniform(0.0, a["axes"]))
        r = turn @ axes
        inertia = r @ np.diag(m) @ r.T
        return 0.5 * (inertia + inertia.T)  # symmetric to the last bit

    def _attitude(self, rng: np.random.Generator) -> np.ndarray:
        a = self.args
        low, high = a.get("low", 0.0), a.get("high", math.pi)
        top = 1.0 - math.cos(high)  # the angle's density under the Haar measure is 1 - cos, rising on [0, pi]
        while True:
            angle = rng.uniform(low, high)
            if top == 0.0 or rng.uniform(0.0, top) <= 1.0 - math.cos(angle):
                break
        turn = np.concatenate([_axis(rng) * math.sin(angle / 2.0), [math.cos(angle / 2.0)]])
        q = _then(turn, np.asarray(a.get("nominal", (0.0, 0.0, 0.0, 1.0)), dtype=float))
        if q[3] < 0.0:
            q = -q  # the same attitude, scalar part >= 0
        if a.get("form") == "mrp":
            return q[:3] / (1.0 + q[3])
        return q


def spacecraft_dispersion(path: Any, name: str, d: Mapping[str, Any]) -> SpacecraftDispersion:
    """The [dispersions.<name>] table of a spacecraft kind, checked; SSPError naming the key."""
    kind = d["distribution"]
    key = f"dispersions.{name!r}"
    need, optional = KINDS[kind], OPTIONAL[kind]
    extra = sorted(set(d) - set(need) - set(optional) - {"distribution"})
    missing = [k for k in need if k not in d]
    if missing or extra:
        raise SSPError(f"{path}: [{key}] ({kind}) needs {', '.join(need) or 'nothing more'}"
                       + (f", may have {', '.join(optional)}" if optional else "")
                       + (f"; missing {', '.join(missing)}" if missing else "")
                       + (f"; unknown {', '.join(extra)}" if extra else ""))

    def number(k, low=-math.inf, high=math.inf):
        v = d[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (low <= v <= high) or not math.isfinite(v):
            raise SSPError(f"{path}: {key}.{k} = {v!r}: expected a number in [{low:g}, {high:g}]")
        return float(v)

    args = dict(d)
    if kind != "cone" and "[" in name:
        raise SSPError(f"{path}: [{key}]: a {kind} dispersion names the vector parameter without an index "
                       f"({name.split('[')[0]}): it sets its elements")
    if kind == "inertia":
        nominal = np.asarray(d["nominal"], dtype=float) if _matrix(d["nominal"]) else None
        if nominal is None or not np.allclose(nominal, nominal.T, rtol=0, atol=1e-12 * np.abs(nominal).max()):
            raise SSPError(f"{path}: {key}.nominal: expected a symmetric 3x3 matrix [[..], [..], [..]] in kg.m2")
        moments = np.linalg.eigvalsh(nominal)
        if moments[0] <= 0 or moments[2] > moments[0] + moments[1] * (1 + 1e-12):
            raise SSPError(f"{path}: {key}.nominal: principal moments {', '.join(f'{m:.6g}' for m in moments)} are "
                           "not a real body's (positive, each at most the sum of the other two)")
        args.update(moments=number("moments", 0.0, 0.5), axes=number("axes", 0.0, math.pi))
    elif kind == "attitude":
        if "nominal" in d:
            q = np.asarray(d["nominal"], dtype=float) if _vector(d["nominal"], 4) else None
            if q is None or abs(np.linalg.norm(q) - 1.0) > 1e-9:
                raise SSPError(f"{path}: {key}.nominal: expected a unit quaternion [x, y, z, w] (scalar last)")
        for k in ("low", "high"):
            if k in d:
                args[k] = number(k, 0.0, math.pi)
        if args.get("low", 0.0) > args.get("high", math.pi):
            raise SSPError(f"{path}: {key}: low > high")
        if d.get("form", "quaternion") not in ("quaternion", "mrp"):
            raise SSPError(f"{path}: {key}.form = {d['form']!r}: expected quaternion or mrp")
    elif kind == "rate":
        args.update(low=number("low", 0.0), high=number("high", 0.0))
        if args["low"] > args["high"]:
            raise SSPError(f"{path}: {key}: low > high")
    else:
        args["half_angle"] = number("half_angle", 0.0, math.pi)
        _check_cone(path, key, d)
    return SpacecraftDispersion(name, kind, args)


def _check_cone(path: Any, key: str, d: Mapping[str, Any]) -> None:
    names = d["parameters"]
    if not (isinstance(names, list) and len(names) == 2 and all(isinstance(n, str) for n in names)):
        raise SSPError(f"{path}: {key}.parameters: expected the two tilt parameters, e.g. "
                       "[\"thrusters.misalignment_1[{i}]\", \"thrusters.misalignment_2[{i}]\"]")
    if "count" in d:
        count = d["count"]
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= 10000:
            raise SSPError(f"{path}: {key}.count = {count!r}: expected an integer from 1 to 10000")
        if not all("{i}" in n for n in names):
            raise SSPError(f"{path}: {key}: count = {count} needs {{i}} in both parameter names")


def _matrix(x: Any) -> bool:
    return isinstance(x, list) and len(x) == 3 and all(_vector(row, 3) for row in x)


def _vector(x: Any, n: int) -> bool:
    return isinstance(x, list) and len(x) == n and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                       for v in x)
