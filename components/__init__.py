"""Pure Python/numpy spacecraft models (no FMI imports).

Each model is a plain class with the state it needs, a `get_state()`/`set_state()` pair
that captures all of it (the FMU wrappers use these for fmi2GetFMUstate/SetFMUstate), and
methods named after what they compute. Conventions: docs/conventions.md (SI units,
scalar-last quaternions q = [q1, q2, q3, q4], A(q) maps N components to B components).
"""
