"""What every matplotlib picture of a run shares: figures with fixed margins, titles placed,
the colour scales and labels of the per-cell fields, cells drawn as an image, and one figure
re-coloured for each next field (:mod:`vares.io.plot`, :mod:`vares.io.surface_plot`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import NamedTuple

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize, TwoSlopeNorm
from matplotlib.image import AxesImage

from ..mechanics.fields import FIELD_DESCRIPTIONS
from .drawing import MARGINS
from .raster import CellImage

__all__ = [
    "FIELD_LABELS",
    "DrawnField",
    "axes_pixels",
    "draw_cells",
    "each_field",
    "field_scale",
    "new_figure",
    "pixel_count",
    "place_title",
    "rgba_bytes",
]

#: Short colour bar labels of the per-cell fields; ``{stress}`` is replaced by the stress unit.
FIELD_LABELS = {
    "det_F": "det F (area erected / pattern) [-]",
    "stretch_max": "larger principal stretch [-]",
    "stretch_min": "smaller principal stretch [-]",
    "stress_max": "larger principal stress [{stress}]",
    "stress_min": "smaller principal stress [{stress}]",
    "warp_stretch": "warp stretch [-]",
    "fill_stretch": "fill stretch [-]",
    "shear_angle": "yarn shear angle [°]",
    "warp_compensation": "warp compensation [%]",
    "fill_compensation": "fill compensation [%]",
    "warp_stress": "warp stress (Cauchy) [{stress}]",
    "fill_stress": "fill stress (Cauchy) [{stress}]",
    "warp_stress_pk2": "warp stress (2nd P-K) [{stress}]",
    "fill_stress_pk2": "fill stress (2nd P-K) [{stress}]",
    "compressed_yarns": "compressed yarns (1 = yes)",
    "wrinkling": "compressive principal stress (1 = yes)",
    "energy": "strain energy",
    "energy_density": "strain energy density [{stress}]",
    "pattern_area": "pattern area",
    "surface_area": "surface area",
    "warp_deviation": "warp deviation from the direction [°]",
    "normal_deviation": "normal deviation from the design (length units)",
    "state": "0 taut, 1 wrinkled, 2 slack",
    "warp_stress_difference": "warp force − intended prestress [{stress}]",
    "fill_stress_difference": "fill force − intended prestress [{stress}]",
}
#: Fields whose colour scale is centred on a neutral value (diverging colours).
_CENTRED = {
    "det_F": 1.0,
    "warp_stretch": 1.0,
    "fill_stretch": 1.0,
    "stretch_max": 1.0,
    "stretch_min": 1.0,
    "shear_angle": 0.0,
    "warp_stress": 0.0,
    "fill_stress": 0.0,
    "warp_stress_pk2": 0.0,
    "fill_stress_pk2": 0.0,
    "stress_max": 0.0,
    "stress_min": 0.0,
    "warp_deviation": 0.0,
    "normal_deviation": 0.0,
    "warp_stress_difference": 0.0,
    "fill_stress_difference": 0.0,
}


#: Spreads below these are round-off: such fields are drawn in one colour (unitless, degrees, %).
_MIN_SPAN = {
    "det_F": 1e-6,
    "warp_stretch": 1e-6,
    "fill_stretch": 1e-6,
    "stretch_max": 1e-6,
    "stretch_min": 1e-6,
    "shear_angle": 1e-4,
    "warp_deviation": 1e-4,
    "warp_compensation": 1e-4,
    "fill_compensation": 1e-4,
}


def _colour_scale(values, field, value_range, stress_scale):
    """Norm and colour map: diverging about the neutral value where there is one; a spread
    below round-off level (per field, or 1e-6 × ``stress_scale`` for stresses) is widened so
    such a field shows as uniform instead of as amplified noise."""
    low, high = value_range if value_range is not None else (np.nanmin(values), np.nanmax(values))
    unit = FIELD_DESCRIPTIONS.get(field, ("", ""))[1]
    span = _MIN_SPAN.get(field, 1e-6 * stress_scale if unit == "stress" and stress_scale else 0)
    if high - low < span:
        middle = 0.5 * (low + high)
        low, high = middle - 0.5 * span, middle + 0.5 * span
    centre = _CENTRED.get(field)
    if centre is not None and low < centre < high:
        return TwoSlopeNorm(centre, low, high), "coolwarm"  # grey, not white, at the centre
    return Normalize(low, high if high > low else low + 1e-12), "viridis"


def new_figure(
    size: tuple[float, float], margins: tuple[float, float, float, float] = MARGINS
) -> tuple[plt.Figure, plt.Axes]:
    """A figure of ``size`` inches with one axes and fixed ``margins``, inches: left, right,
    bottom, top (room for a title, tick labels and axis labels; a colour bar takes its room from
    the axes), by default the run's preview's. A constrained layout took 0.1 s of a 0.25 s
    picture, as of a convergence plot (its log axis has some 90 ticks to measure), and a report
    has nine."""
    fig, ax = plt.subplots(figsize=size)
    width, height = size
    left, right, bottom, top = margins
    fig.subplots_adjust(
        left=left / width, right=1 - right / width, bottom=bottom / height, top=1 - top / height
    )
    return fig, ax


def place_title(ax: plt.Axes, title: str | None) -> None:
    """The title just above the axes. Placed, not left to matplotlib to place: it would measure
    every tick label to find whether any is on top (none is), 13 ms of a 0.12 s convergence
    plot."""
    if title:
        ax.set_title(title, y=1.0)


def pixel_count(width: float, height: float, dpi: float) -> int:
    """Pixels along the longer side of axes ``width`` × ``height`` inches saved at ``dpi``: a
    drawing with equal axes spans at most that many, so its cells rasterised at this count are
    drawn without being enlarged (blocky) nor shrunk (work for nothing)."""
    return max(16, round(dpi * max(width, height)))


def axes_pixels(ax: plt.Axes, dpi: float) -> int:
    """:func:`pixel_count` of the axes ``ax`` as they are placed in their figure."""
    box = ax.get_position()
    width, height = ax.figure.get_size_inches()
    return pixel_count(box.width * width, box.height * height, dpi)


def rgba_bytes(rgba: np.ndarray) -> np.ndarray:
    """RGBA colours, floats 0 … 1, as bytes (an image of bytes is drawn without checks for NaN)."""
    return np.round(255 * np.asarray(rgba)).astype(np.uint8)


def draw_cells(ax: plt.Axes, image: CellImage, colours: np.ndarray) -> AxesImage:
    """The cells as an image, each in its colour (``(cells, 4)`` RGBA bytes)."""
    return ax.imshow(
        image.colours(colours),
        extent=image.extent,
        origin="lower",
        interpolation="nearest",
        zorder=1,
    )


class DrawnField(NamedTuple):
    """A drawn field: its figure, the image of the cells and its colour bar, and how per-cell
    values in a colour scale become that image."""

    figure: plt.Figure
    picture: object
    bar: object
    paint: Callable[[ScalarMappable, np.ndarray], np.ndarray]


def field_scale(
    values: np.ndarray,
    field: str | None,
    value_range: Sequence[float] | None,
    stress_scale: float | None,
    stress_unit: str,
) -> tuple[ScalarMappable, str]:
    """The colour scale per-cell values are drawn in, and its label."""
    norm, cmap = _colour_scale(values, field, value_range, stress_scale)
    label = FIELD_LABELS.get(field, field or "").replace("{stress}", stress_unit)
    return ScalarMappable(norm=norm, cmap=cmap), label


def each_field(
    fields: Mapping[str, np.ndarray],
    titles: Mapping[str, str] | None,
    draw: Callable[[str, np.ndarray, str], DrawnField],
    stress_scale: float | None,
    stress_unit: str,
) -> Iterator[tuple[str, plt.Figure]]:
    """Every field on one figure: the first ``draw``-n, each next re-colouring its cells and
    colour bar and re-titling it; the figure closed at the end."""
    drawn = None
    try:
        for name, values in fields.items():
            values = np.asarray(values, dtype=float)
            title = name if titles is None else titles[name]
            if drawn is None:
                drawn = draw(name, values, title)
            else:
                shown, label = field_scale(values, name, None, stress_scale, stress_unit)
                drawn.picture.set_data(drawn.paint(shown, values))
                drawn.bar.mappable = shown
                drawn.bar.update_normal()  # the new scale, its ticks and their labels
                drawn.bar.set_label(label)
                place_title(drawn.figure.axes[0], title)
            yield name, drawn.figure
    finally:
        if drawn is not None:
            plt.close(drawn.figure)
