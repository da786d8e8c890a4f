"""Packages import their names when first used (vares/_lazy.py): every exported name resolves,
and a plain `import vares` or a pattern's work loads no more than it needs."""

from __future__ import annotations

import importlib
import importlib.util
import subprocess
import sys

import pytest

from vares._lazy import _exports

PACKAGES = [
    "vares",
    "vares.analysis",
    "vares.app",
    "vares.geometry",
    "vares.io",
    "vares.mechanics",
    "vares.solver",
    "vares.structures",
]


def _exports_a_module(package: str, name: str) -> bool:
    """Whether ``package.name`` is a module by its lazy imports (``from . import examples``,
    or a name re-exported from a package that imports it so)."""
    path = importlib.util.find_spec(package).origin
    with open(path, encoding="utf-8") as source:
        exports = _exports(source.read())
    if name not in exports:
        return False
    module, attribute = exports[name]
    if not attribute:
        return True
    source_package = importlib.util.resolve_name(module, package)
    spec = importlib.util.find_spec(source_package)
    return spec.submodule_search_locations is not None and _exports_a_module(
        source_package, attribute
    )


@pytest.mark.parametrize("name", PACKAGES)
def test_every_exported_name_resolves(name: str) -> None:
    package = importlib.import_module(name)
    assert package.__all__, name
    for attribute in package.__all__:
        value = getattr(package, attribute)
        assert value is not None
        if _exports_a_module(name, attribute):  # from . import examples
            assert isinstance(value, type(sys)), f"{name}.{attribute}"
        elif not attribute.startswith("__"):
            assert not isinstance(value, type(sys)), f"{name}.{attribute} is a module"
    assert set(package.__all__) <= set(dir(package))


def test_a_name_shared_with_its_module_is_the_function() -> None:
    """Importing the module ``vares.analysis.evaluate`` leaves ``vares.analysis.evaluate`` the
    function, as the eager ``from .evaluate import evaluate`` did; in a fresh process, the
    package's import does not import that module."""
    loaded = _loaded_after("import vares.analysis")
    assert "vares.analysis.evaluate" not in loaded
    import vares.analysis.evaluate  # the module imported first: the package keeps the function
    import vares.io.summary
    from vares.analysis.evaluate import PatternEvaluation

    assert callable(vares.evaluate) and vares.evaluate.__name__ == "evaluate"
    assert vares.analysis.evaluate is vares.evaluate
    assert callable(vares.io.summary) and vares.io.summary.__name__ == "summary"
    assert PatternEvaluation.__module__ == "vares.analysis.evaluate"


def test_subpackages_and_unknown_names() -> None:
    import vares

    assert vares.io.plot.__name__ == "vares.io.plot"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        vares.nothing  # noqa: B018


def test_lazy_block_accepts_only_relative_imports() -> None:
    assert _exports("if TYPE_CHECKING:\n    from .a import b as c\n    from . import d\n") == {
        "c": (".a", "b"),
        "d": (".d", ""),
    }
    with pytest.raises(ImportError):
        _exports("if TYPE_CHECKING:\n    import numpy\n")


def _loaded_after(code: str) -> set[str]:
    done = subprocess.run(
        [sys.executable, "-c", code + "\nimport sys\nprint(' '.join(sorted(sys.modules)))"],
        capture_output=True,
        text=True,
        check=True,
    )
    return set(done.stdout.split())


def test_import_vares_loads_nothing_heavy() -> None:
    loaded = _loaded_after("import vares")
    assert not {"numpy", "scipy", "numba", "matplotlib"} & loaded


def test_a_solve_does_not_load_the_erection_structures_or_plots() -> None:
    loaded = _loaded_after(
        "import vares\n"
        "vares.solve(vares.examples.hypar(n=4), vares.materials.NeoHooke(E=1000.0, nu=0.3))"
    )
    assert "vares.solver.api" in loaded
    assert (
        not {
            "vares.analysis.erection",
            "vares.structures.matching",
            "matplotlib",
            "scipy.spatial",
        }
        & loaded
    )
