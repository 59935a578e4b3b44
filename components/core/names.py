"""The FMI structured names of vector and matrix variables (`name[i]`, `name[i,j]`, 1-based), spelled
once for the wrappers that declare them and the mission definition that records them."""
from typing import Tuple

Names = Tuple[str, ...]


def element_names(name: str, n: int) -> Names:
    """name[1] .. name[n]."""
    return tuple(f"{name}[{i}]" for i in range(1, n + 1))


def matrix_names(name: str, rows: int, cols: int) -> Tuple[Names, ...]:
    """((name[1,1], name[1,2], ..), ..), by row."""
    return tuple(tuple(f"{name}[{i},{j}]" for j in range(1, cols + 1)) for i in range(1, rows + 1))
