"""Cutting lines drawn by the user: polylines from a text file or the curves of a Rhino file.

A text file holds one point ``x y z`` per line (commas or spaces), a blank line between two
curves; ``#`` starts a comment. In a ``.3dm`` file every curve object (polyline, line, arc,
NURBS curve) becomes one polyline: polylines and lines by their own points, other curves sampled
at 200 points; ``layer`` keeps only the curves on that layer (its name or full path).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["read_curves"]

#: Points a smooth curve of a 3dm file is sampled at.
CURVE_SAMPLES = 200


def read_curves(path: str | Path, layer: str | None = None) -> list[np.ndarray]:
    """The polylines ``(k, 3)`` of a curves file (module docs).

    Raises
    ------
    FileNotFoundError
        No such file.
    ValueError
        A line that is no point, a curve of fewer than two points, or no curve at all.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    if path.suffix.lower() == ".3dm":
        curves = _rhino_curves(path, layer)
    else:
        if layer is not None:
            raise ValueError(f"{path}: a layer is given, but this is no 3dm file")
        curves = _text_curves(path)
    if not curves:
        where = f" on layer {layer!r}" if layer is not None else ""
        raise ValueError(f"{path} has no curves{where}")
    return curves


def _text_curves(path: Path) -> list[np.ndarray]:
    curves, current = [], []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            if current:
                curves.append(current)
            current = []
            continue
        try:
            values = [float(v) for v in line.replace(",", " ").split()]
        except ValueError:
            raise ValueError(f"{path}:{number}: expected 'x y z'; got {raw.strip()!r}") from None
        if len(values) != 3:
            raise ValueError(f"{path}:{number}: expected three numbers 'x y z'; got {raw!r}")
        current.append(values)
    if current:
        curves.append(current)
    out = [np.array(c, dtype=float) for c in curves]
    for index, curve in enumerate(out, start=1):
        if len(curve) < 2:
            raise ValueError(f"{path}: curve {index} has a single point")
    return out


def _rhino_curves(path: Path, layer: str | None) -> list[np.ndarray]:
    import rhino3dm

    model = rhino3dm.File3dm.Read(str(path))
    if model is None:
        raise ValueError(f"cannot read {path}: not a Rhino 3dm file, or a damaged one")
    layers = {i: (model.Layers[i].Name, model.Layers[i].FullPath) for i in range(len(model.Layers))}
    if layer is not None and not any(layer in names for names in layers.values()):
        known = ", ".join(sorted({n[1] for n in layers.values()})) or "none"
        raise ValueError(f"{path} has no layer {layer!r} (layers: {known})")
    curves = []
    for obj in model.Objects:
        geometry = obj.Geometry
        if not isinstance(geometry, rhino3dm.Curve):
            continue
        if layer is not None and layer not in layers.get(obj.Attributes.LayerIndex, ()):
            continue
        curves.append(_curve_points(geometry, rhino3dm))
    return curves


def _curve_points(curve, rhino3dm) -> np.ndarray:
    if isinstance(curve, rhino3dm.PolylineCurve):
        points = [curve.Point(i) for i in range(curve.PointCount)]
    else:
        low, high = curve.Domain.T0, curve.Domain.T1
        points = [curve.PointAt(t) for t in np.linspace(low, high, CURVE_SAMPLES)]
    return np.array([[p.X, p.Y, p.Z] for p in points], dtype=float)
