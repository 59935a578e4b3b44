"""Input and parameter checks shared by the models: positive numbers, finite vectors and parameter sets."""
import math


def finite_parameters(defaults, params=None):
    """`defaults` completed with `params`, every value a finite float.

    ValueError names an unknown parameter or a value that is not a finite number; the caller
    checks each value's own range."""
    p = dict(defaults)
    for k, v in (params or {}).items():
        if k not in p:
            raise ValueError(f"unknown parameter {k!r}")
        p[k] = v
    for k, v in p.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"parameter {k} = {v!r} must be a finite number")
        p[k] = float(v)
    return p


def finite_vector(v, n, what, note=None):
    """v as a tuple of n finite floats; ValueError naming `what` (and `note`, e.g. its unit)."""
    try:
        t = tuple(map(float, v))
    except (TypeError, ValueError):
        suffix = f" ({note})" if note else ""
        raise ValueError(f"{what} must be {n} numbers{suffix}, got {v!r}") from None
    if len(t) != n or not all(map(math.isfinite, t)):
        suffix = f" ({note})" if note else ""
        raise ValueError(f"{what} {list(t)} must be {n} finite numbers{suffix}")
    return t


def _finite_number(name, value, unit, requirement, accepts):
    """value as a float for which accepts(x) holds; ValueError '<name> = <value> <unit> must be
    <requirement>' for anything else, a Boolean or a non-number included."""
    text = f"{name} = {value!r}{' ' + unit if unit else ''} must be {requirement}"
    if isinstance(value, bool):
        raise ValueError(text)
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(text) from None
    if not (math.isfinite(x) and accepts(x)):
        raise ValueError(text)
    return x


def positive(name, value, unit=""):
    """value as a float > 0; ValueError naming `name` (and its unit) for anything else, a Boolean
    or a non-number included."""
    return _finite_number(name, value, unit, "a finite positive number", lambda x: x > 0.0)


def non_negative(name, value, unit=""):
    """value as a float >= 0; ValueError naming `name` (and its unit) for anything else, a Boolean
    or a non-number included."""
    return _finite_number(name, value, unit, "a finite number >= 0", lambda x: x >= 0.0)
