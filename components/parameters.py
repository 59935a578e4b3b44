"""Parameter sets of the models that take a dict of named numbers (the ACS models)."""
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
