"""Parametrised example surfaces, and the registries the command line names them by.

``cylinder160``, ``hypar``, ``sail``, ``tent``, ``rib30``, ``saddle``, ``conic-tent``
    The named examples (:mod:`vares.geometry.example_surfaces`): the seed paper's cylinder
    segment, a hyperbolic paraboloid, a four-point sail and a panel of a conic tent, a curved
    composite rib, and the whole membranes of the cutting examples.
``double-dome``
    A double-dome mould (two domes joined by a saddle, on a flat flange; mm) for composite plies
    (:mod:`vares.geometry.double_dome`).
``hypar-strips``, ``catenoid-band``
    Example structures, surfaces cut into panels (:mod:`vares.geometry.example_structures`).
``robustness_suite``, ``real_world_suite``
    The hard and awkward surfaces every strategy change is checked on, and surfaces as they come
    from outside: a scan and a CAD roof in millimetres (:mod:`vares.geometry.hard_surfaces`).

Every generator is importable from here, as from its own module.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .double_dome import double_dome, double_dome_height
from .example_structures import catenoid_band, hypar_strips, irregular_hypar_strips
from .example_surfaces import (
    conic_tent,
    cylinder160,
    cylinder_arc_length,
    four_point_sail,
    grid_cells,
    hypar,
    rib30,
    saddle,
    tent_roof,
)
from .hard_surfaces import (
    bumpy,
    cad_roof_mm,
    cap_over_square,
    catenoid_section,
    cone_segment,
    graded_hypar,
    irregular_cap,
    real_world_suite,
    robustness_suite,
    ruffled_fan,
    scan_like,
    spherical_cap,
)
from .mesh import SurfaceMesh

__all__ = [
    "CUT_EXAMPLES",
    "EXAMPLES",
    "EXAMPLE_PLANES",
    "PANEL_NAMES",
    "STRUCTURE_EXAMPLES",
    "bumpy",
    "cad_roof_mm",
    "cap_over_square",
    "catenoid_band",
    "catenoid_section",
    "cone_segment",
    "conic_tent",
    "cylinder160",
    "cylinder_arc_length",
    "double_dome",
    "double_dome_height",
    "four_point_sail",
    "graded_hypar",
    "grid_cells",
    "hypar",
    "hypar_strips",
    "irregular_cap",
    "irregular_hypar_strips",
    "real_world_suite",
    "rib30",
    "robustness_suite",
    "ruffled_fan",
    "saddle",
    "scan_like",
    "spherical_cap",
    "tent_roof",
]


#: Example generators by name (used by ``vares example``).
EXAMPLES: dict[str, Callable[..., SurfaceMesh]] = {
    "cylinder160": cylinder160,
    "double-dome": double_dome,
    "hypar": hypar,
    "rib30": rib30,
    "sail": four_point_sail,
    "tent": conic_tent,
}
#: Whole surfaces to cut into strips of roll width (``vares cut --example``).
CUT_EXAMPLES: dict[str, Callable[..., SurfaceMesh]] = {"saddle": saddle, "conic-tent": tent_roof}
#: Example structures by name: generators of a mesh and a panel id per cell (``vares panels``).
STRUCTURE_EXAMPLES: dict[str, Callable[..., tuple[SurfaceMesh, np.ndarray]]] = {
    "hypar-strips": hypar_strips,
    "catenoid-band": catenoid_band,
}
#: What the panels of each example structure are called (name-1, name-2, …).
PANEL_NAMES = {"hypar-strips": "strip", "catenoid-band": "gore"}
#: The initial-guess plane each example is meant to be patterned with.
EXAMPLE_PLANES = {"cylinder160": "xy"}
