"""Rigid modes of a pattern: the motions that leave the energy unchanged, and how they are held.

Translations of the pattern never change the energy; a rotation changes it only when the energy
depends on the yarn directions (an anisotropic law or a prestress along the yarns). Newton's
method needs them removed: the translation by holding one node, the rotation by holding a second
coordinate (``"fixed"``), by one linear constraint (``"held"``), or not at all (``"free"``).
"""

from __future__ import annotations

import numpy as np

__all__ = ["ROTATIONS", "rigid_modes"]

ROTATIONS = ("fixed", "held", "free")


def rigid_modes(coordinates: np.ndarray, rotation: str) -> tuple[np.ndarray, np.ndarray | None]:
    """Free-dof mask ``(2 n,)`` and linear rotation constraint that remove a pattern's rigid modes.

    The node with the smallest pattern x is held (translations). The rotation is

    - ``"fixed"`` (isotropic laws, for which it is a zero mode): the y coordinate of the node
      with the largest x is held too;
    - ``"held"`` (anisotropic laws with a given orientation): the mean rotation about the
      centroid stays that of ``coordinates``, a linear constraint ``cᵀΔX = 0`` over the free dofs
      (``c`` the unit rigid rotation field, blind to translations, so the choice of the held node
      does not matter) whose reaction is a torque spread over the pattern like a rigid rotation,
      not a point force;
    - ``"free"``: the energy chooses it.

    Returns the mask and ``c`` (``None`` unless ``"held"``).
    """
    if rotation not in ROTATIONS:
        raise ValueError(f"unknown rotation mode {rotation!r}; choose from {', '.join(ROTATIONS)}")
    free = np.ones(coordinates.size, dtype=bool)
    first = int(np.argmin(coordinates[:, 0]))
    free[2 * first : 2 * first + 2] = False
    if rotation == "fixed":
        free[2 * int(np.argmax(coordinates[:, 0])) + 1] = False
        return free, None
    if rotation == "free":
        return free, None
    arm = coordinates - coordinates.mean(axis=0)
    field_ = np.column_stack([-arm[:, 1], arm[:, 0]]).ravel()[free]
    return free, field_ / np.linalg.norm(field_)
