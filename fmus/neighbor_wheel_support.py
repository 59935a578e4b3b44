"""What the wheel FMUs share (ReactionWheelArray, WheelTorqueDistribution): the wheel count and
spin-axis parameters, with the same names and defaults in both so that one parameter set serves
both, and the fixed six output slots."""
from components.acs import reaction_wheel_array as rwa
from components.core.names import matrix_names

SLOTS = rwa.MAX_WHEELS


def wheel_geometry_parameters(slave, count_text):
    """wheel_count and spin_axis_B[6,3] (default: the four-wheel pyramid about +z and spare x, y)."""
    slave.parameter("wheel_count", 4, None, f"{count_text}, 1..{SLOTS} (slots 1..wheel_count)", int)
    axes = rwa.default_axes()
    for i, row in enumerate(matrix_names("spin_axis_B", SLOTS, 3)):
        for j in range(3):
            slave.parameter(row[j], axes[i][j], "1", f"Spin axis of wheel {i + 1} in B, normalized "
                            f"(non-zero; component {j + 1})")


def wheel_axes(values):
    """(wheel_count, the used spin axes) from the parameter values; ValueError on a bad count."""
    count = values["wheel_count"]
    if not 1 <= count <= SLOTS:
        raise ValueError(f"wheel_count = {count} must be in 1..{SLOTS}")
    return count, [[values[e] for e in row] for row in matrix_names("spin_axis_B", SLOTS, 3)][:count]


def padded(values):
    """A per-wheel array in the six output slots (the unused ones zero)."""
    v = [0.0] * SLOTS
    v[:len(values)] = values.tolist()
    return v
