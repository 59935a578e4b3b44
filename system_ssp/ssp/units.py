"""Physical units as SI base-unit exponents plus an affine map to SI.

A unit is a `Unit(name, exponents, factor, offset)` where the SI value is
`factor * value + offset` and `exponents` are the exponents of `SI_BASE_UNITS`
(kg, m, s, A, K, mol, cd, rad): the order FMI 2.0 `BaseUnit` and SSP `ssc:BaseUnit` share, and
the one place the product spells it.

`BUILTIN` is the product's unit table: every unit its FMUs declare (build_fmus.py writes their
`UnitDefinitions` from it) and common SI-derived units. The master looks a unit up in the SSD's
`ssd:Units`, then in the FMU's `UnitDefinitions`, then here, so a connection between two FMUs
that only name their units (e.g. "m" and "km") still converts correctly.
"""
import math
from typing import Dict, NamedTuple, Optional, Tuple

SI_BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


class Unit(NamedTuple):
    name: str
    exponents: Tuple[int, ...]  # of SI_BASE_UNITS
    factor: float
    offset: float


def make_unit(name: str, factor: float = 1.0, offset: float = 0.0, **exps: int) -> Unit:
    unknown = set(exps) - set(SI_BASE_UNITS)
    if unknown:
        raise ValueError(f"unit {name!r}: unknown base unit(s) {sorted(unknown)}")
    return Unit(name, tuple(int(exps.get(b, 0)) for b in SI_BASE_UNITS), float(factor), float(offset))


_DEG = math.pi / 180.0
BUILTIN = {u.name: u for u in [
    make_unit("1"), make_unit("-"), make_unit("byte"), make_unit("byte/s", s=-1),
    make_unit("m", m=1), make_unit("mm", 1e-3, m=1), make_unit("cm", 1e-2, m=1), make_unit("km", 1e3, m=1),
    make_unit("s", s=1), make_unit("ms", 1e-3, s=1), make_unit("min", 60.0, s=1), make_unit("h", 3600.0, s=1),
    make_unit("d", 86400.0, s=1),
    make_unit("kg", kg=1), make_unit("g", 1e-3, kg=1),
    make_unit("rad", rad=1), make_unit("deg", _DEG, rad=1),
    make_unit("rad/s", rad=1, s=-1), make_unit("deg/s", _DEG, rad=1, s=-1),
    make_unit("rad/s2", rad=1, s=-2), make_unit("deg/s2", _DEG, rad=1, s=-2),
    make_unit("m/s", m=1, s=-1), make_unit("km/s", 1e3, m=1, s=-1), make_unit("m/s2", m=1, s=-2),
    make_unit("m2", m=2), make_unit("m3", m=3), make_unit("kg.m2", kg=1, m=2), make_unit("kg/m3", kg=1, m=-3),
    make_unit("N", kg=1, m=1, s=-2), make_unit("mN", 1e-3, kg=1, m=1, s=-2),
    make_unit("N.m", kg=1, m=2, s=-2), make_unit("mN.m", 1e-3, kg=1, m=2, s=-2),
    make_unit("N.m.s", kg=1, m=2, s=-1), make_unit("N.m.s2", kg=1, m=2),
    make_unit("N.s", kg=1, m=1, s=-1), make_unit("kg/s", kg=1, s=-1),
    make_unit("J", kg=1, m=2, s=-2), make_unit("kJ", 1e3, kg=1, m=2, s=-2), make_unit("Wh", 3600.0, kg=1, m=2, s=-2),
    make_unit("W", kg=1, m=2, s=-3), make_unit("mW", 1e-3, kg=1, m=2, s=-3), make_unit("W/m2", kg=1, s=-3),
    make_unit("Pa", kg=1, m=-1, s=-2), make_unit("kPa", 1e3, kg=1, m=-1, s=-2),
    make_unit("K", K=1), make_unit("degC", 1.0, 273.15, K=1),
    make_unit("A", A=1), make_unit("V", kg=1, m=2, s=-3, A=-1), make_unit("T", kg=1, s=-2, A=-1),
    make_unit("nT", 1e-9, kg=1, s=-2, A=-1), make_unit("A.m2", A=1, m=2),
    make_unit("Hz", s=-1), make_unit("1/s", s=-1), make_unit("1/K", K=-1), make_unit("m3/s2", m=3, s=-2),
]}


def base_unit_attributes(unit: Unit) -> Dict[str, int]:
    """{base unit: exponent} of the non-zero exponents, in SI_BASE_UNITS order (the attributes of
    an FMI BaseUnit / ssc:BaseUnit element)."""
    return {b: e for b, e in zip(SI_BASE_UNITS, unit.exponents) if e}


def conversion(src: Unit, dst: Unit) -> Optional[Tuple[float, float]]:
    """(factor, offset) mapping a value in unit `src` to unit `dst`; None if dimensions differ."""
    if src.exponents != dst.exponents:
        return None
    factor = src.factor / dst.factor
    offset = (src.offset - dst.offset) / dst.factor
    return factor, offset


def describe(unit: Unit) -> str:
    parts = [f"{b}^{e}" if e != 1 else b for b, e in zip(SI_BASE_UNITS, unit.exponents) if e]
    return "*".join(parts) or "1"
