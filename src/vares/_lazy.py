"""A package's names imported when first used.

A package ``__init__`` lists what it offers as ordinary imports under ``if TYPE_CHECKING:``
(so readers, type checkers and editors see them) and ends with

    __getattr__, __dir__, __all__ = lazy_exports(__name__, __file__)

which reads those imports from the file and performs each only when its name is first asked
for. ``vares pattern`` then imports only the modules its work needs: not the erection analysis,
the structures, the seam matching and their libraries (docs/benchmarks.md, the small job).
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import sys
import types
from collections.abc import Callable
from pathlib import Path

__all__ = ["lazy_exports"]


def _exports(source: str) -> dict[str, tuple[str, str]]:
    """Name → (relative module, attribute) of the ``from … import …`` statements under
    ``if TYPE_CHECKING:`` in a module's ``source``; an attribute ``""`` is the module itself
    (``from . import examples``)."""
    exports = {}
    for node in ast.parse(source).body:
        if not (isinstance(node, ast.If) and ast.unparse(node.test) == "TYPE_CHECKING"):
            continue
        for statement in node.body:
            if not isinstance(statement, ast.ImportFrom) or statement.level == 0:
                raise ImportError("only relative 'from … import …' belong in the lazy block")
            base = "." * statement.level + (statement.module or "")
            for alias in statement.names:
                name = alias.asname or alias.name
                if statement.module is None:  # from . import module
                    exports[name] = (base + alias.name, "")
                else:
                    exports[name] = (base, alias.name)
    return exports


class _Package(types.ModuleType):
    """A package some of whose names are those of their own modules (``evaluate`` from
    ``.evaluate``): importing such a module, which sets it as the package's attribute of that
    name, leaves the name to the function, as an eager ``from .evaluate import evaluate`` in
    the ``__init__`` did."""

    def __setattr__(self, name: str, value: object) -> None:
        if isinstance(value, types.ModuleType) and name in self.__dict__.get("_shadowing", ()):
            return
        super().__setattr__(name, value)


def lazy_exports(
    package: str, file: str
) -> tuple[Callable[[str], object], Callable[[], list[str]], list[str]]:
    """``__getattr__``, ``__dir__`` and ``__all__`` of the package ``package`` whose
    ``__init__`` is ``file``, from its ``if TYPE_CHECKING:`` imports."""
    exports = _exports(Path(file).read_text(encoding="utf-8"))
    module = sys.modules[package]
    module.__dict__["_shadowing"] = frozenset(
        name
        for name, (module_name, attribute) in exports.items()
        if attribute and module_name.rsplit(".", 1)[-1] == name
    )
    module.__class__ = _Package

    def __getattr__(name: str) -> object:
        try:
            module_name, attribute = exports[name]
        except KeyError:  # a subpackage or module, as ``vares.io`` (imported as it is named)
            if name.startswith("_") or importlib.util.find_spec(f"{package}.{name}") is None:
                raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
            return importlib.import_module(f"{package}.{name}")
        module = importlib.import_module(module_name, package)
        value = getattr(module, attribute) if attribute else module
        setattr(sys.modules[package], name, value)  # asked once
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(exports))

    return __getattr__, __dir__, sorted(exports)
