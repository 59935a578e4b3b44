"""Attributes kept in a model's state array `x`: properties for models whose compiled or native
step reads and writes that array (components.core.native), so the attributes stay what they were
for the Python code around them."""


def view(at, n=1):
    """x[at] as a float (n = 1), or x[at:at + n] as a tuple of floats."""
    if n == 1:
        return property(lambda self: float(self.x[at]), lambda self, value: self.x.__setitem__(at, value))
    window = slice(at, at + n)
    return property(lambda self: tuple(self.x[window].tolist()),
                    lambda self, value: self.x.__setitem__(window, value))


def flag(at):
    """x[at] as a bool (1.0 true, 0.0 false)."""
    return property(lambda self: bool(self.x[at]), lambda self, value: self.x.__setitem__(at, bool(value)))


def optional(at, n, present_at):
    """x[at:at + n] as a tuple of floats, or None while x[present_at] is 0 (setting None clears it)."""
    window = slice(at, at + n)

    def get(self):
        return tuple(self.x[window].tolist()) if self.x[present_at] else None

    def put(self, value):
        if value is not None:
            self.x[window] = value
        self.x[present_at] = value is not None

    return property(get, put)
