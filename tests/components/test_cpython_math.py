"""cpython_math.hypot, compiled, against CPython's math.hypot on this interpreter: the same bits
over magnitudes from the smallest normal number to near overflow, very unequal and equal legs,
signs, zeros, infinities and NaN (numba's own math.hypot, the C library's, differs in the last bit
here). Where both legs are subnormal it can differ in the last bit (cpython_math's docstring)."""
import math
import sys

import numpy as np
import pytest

from components.core import cpython_math, jit

pytestmark = pytest.mark.skipif(not jit.ENABLED, reason="numba is not used here: plain Python calls math.hypot")


def test_compiled_hypot_gives_cpython_bits():
    rng = np.random.default_rng(2026)
    n = 100_000
    a = rng.standard_normal(n) * 10.0 ** rng.uniform(-305, 305, n)
    b = np.concatenate([a[: n // 2] * rng.uniform(0.0, 1.0, n // 2) * 10.0 ** rng.uniform(-20, 0, n // 2),
                        rng.standard_normal(n - n // 2) * 10.0 ** rng.uniform(-320, 305, n - n // 2)])
    special = [(0.0, 0.0), (-0.0, 0.0), (2.3e-308, 5e-324), (1e308, 1e308), (-3.0, 4.0), (1e-200, 3e-310),
               (math.inf, math.nan), (math.nan, -math.inf), (math.nan, 1.0), (1e-4, 1.5e-3)]
    pairs = [(x, y) for x, y in zip(a.tolist(), b.tolist()) if max(abs(x), abs(y)) >= sys.float_info.min] + special
    compiled = jit.loaded(cpython_math.hypot)  # (a Kernel, or numba's dispatcher once a compiled caller took it)
    differ = [(x, y) for x, y in pairs if not _same(compiled(x, y), math.hypot(x, y))]
    assert not differ, f"{len(differ)} of {len(pairs)} differ, e.g. {differ[:3]}"
    # the C library's hypot, which numba's math.hypot calls, is what this replaces
    library = jit._numba().njit(lambda x, y: math.hypot(x, y))
    assert any(not _same(library(x, y), math.hypot(x, y)) for x, y in pairs[:20_000])


def _same(x, y):
    return x == y or (math.isnan(x) and math.isnan(y))
