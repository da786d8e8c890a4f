"""Reference elements by meshio cell type."""

from .base import ReferenceElement, determinant, inverse
from .quad import QUAD
from .triangle import TRIANGLE

#: Supported cell types: meshio name → reference element.
ELEMENTS: dict[str, ReferenceElement] = {"triangle": TRIANGLE, "quad": QUAD}

__all__ = ["ELEMENTS", "QUAD", "TRIANGLE", "ReferenceElement", "determinant", "inverse"]
