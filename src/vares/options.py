"""Declared settings: every option with its default, its bounds and its help, written once.

An options class is a frozen dataclass whose fields are made with :func:`option`. The field
holds the default; its :class:`Spec` holds the kind of value, the bounds, the help text, the
job-file section and the command-line flag. Everything that takes settings is derived from these
declarations:

- the Python API: :func:`takes_options` gives a function one keyword argument per field (with
  the field's default and help) and turns them into the options object;
- job files: every key of a table is checked against the fields of the options classes that
  table holds (``vares.app.job``); an unknown key is refused with the closest valid spelling;
- the command line: ``vares.app.cli`` makes one flag per field from the same spec.

An option that means the same in another table (a laminate's darts, those of ``vares drape``) is
declared once and taken over there with :func:`reused`: its kind, choices and bounds stay the
original's; the other table may say in its help what it does with it.

Values are checked and normalised when an options object is made (sequences become tuples, ints
become floats where a float is meant), so every entry point accepts and refuses the same values.
"""

from __future__ import annotations

import difflib
import inspect
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import MISSING, dataclass, field, fields, replace
from os import PathLike
from typing import Any, ClassVar, Self

__all__ = [
    "Options",
    "OptionsError",
    "Spec",
    "option",
    "reused",
    "split_settings",
    "suggest",
    "takes_options",
]

#: Kinds of option values and how they are described in messages.
KINDS = {
    "bool": "true or false",
    "int": "an integer",
    "float": "a number",
    "str": "a string",
    "vector": "three numbers x, y, z (not all zero)",
    "plane": "a plane name or a normal vector x, y, z (not all zero)",
    "floats": "a list of numbers",
    "strings": "a list of strings",
    "path": "a file or folder path",
    "paths": "a list of file paths",
}


class OptionsError(ValueError):
    """A setting is unknown or not admissible.

    ``key`` is the setting's name (``None`` for rules between settings), ``problem`` the message
    without it; ``str()`` gives both. Front ends name the key their own way (``--max-iterations``,
    ``[solver] max_iterations``).
    """

    def __init__(self, key: str | None, problem: str) -> None:
        super().__init__(f"{key} {problem}" if key else problem)
        self.key = key
        self.problem = problem


@dataclass(frozen=True)
class Spec:
    """What an option accepts and how it is presented.

    ``kind`` is one of :data:`KINDS`; ``choices`` the admissible strings (of a ``str`` or each
    item of ``strings``; of ``floats``, the names it takes beside a list, e.g. ``"auto"``);
    ``minimum`` an inclusive lower bound and ``positive`` a strict one (> 0);
    ``optional`` admits ``None``. ``section`` is the job-file table the option lives in,
    ``flags`` its command-line names (``None``: ``--name-with-dashes``; ``()``: not a flag).
    """

    kind: str
    help: str
    section: str
    choices: tuple[str, ...] | None = None
    minimum: float | None = None
    positive: bool = False
    optional: bool = False
    flags: tuple[str, ...] | None = None

    def bounds(self) -> str:
        """The bounds as text (for help and messages)."""
        if self.choices is not None:
            return "one of " + ", ".join(self.choices)
        if self.positive:
            return "> 0"
        if self.minimum is not None:
            return f"≥ {self.minimum:g}"
        return ""

    def check(self, key: str, value: Any) -> Any:
        """The value normalised (tuples, floats), or :class:`OptionsError` naming ``key``."""
        if value is None:
            if self.optional:
                return None
            raise OptionsError(key, "must be given")
        checker = getattr(self, f"_check_{self.kind}")
        return checker(key, value)

    def _refuse(self, key: str, value: Any, expected: str | None = None) -> OptionsError:
        return OptionsError(key, f"must be {expected or KINDS[self.kind]}; got {value!r}")

    def _check_bool(self, key: str, value: Any) -> bool:
        if not isinstance(value, bool):
            raise self._refuse(key, value)
        return value

    def _number(self, key: str, value: Any, integer: bool) -> int | float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            if not (hasattr(value, "dtype") and value.shape == ()):  # numpy scalars
                raise self._refuse(key, value)
            value = value.item()
        if integer and not (isinstance(value, int) or float(value).is_integer()):
            raise self._refuse(key, value)
        value = int(value) if integer else float(value)
        if not math.isfinite(value):
            raise self._refuse(key, value, "a finite number")
        if self.positive and not value > 0:
            raise OptionsError(key, f"must be > 0; got {value!r}")
        if self.minimum is not None and value < self.minimum:
            raise OptionsError(key, f"must be ≥ {self.minimum:g}; got {value!r}")
        return value

    def _check_int(self, key: str, value: Any) -> int:
        return self._number(key, value, integer=True)

    def _check_float(self, key: str, value: Any) -> float:
        return self._number(key, value, integer=False)

    def _choice(self, key: str, value: Any) -> str:
        if not isinstance(value, str):
            raise self._refuse(key, value, "a string")
        if self.choices is None or value in self.choices:
            return value
        same = [c for c in self.choices if c.lower() == value.lower()]
        if same:
            return same[0]
        raise OptionsError(
            key, f"must be {self.bounds()}; got {value!r}{suggest(value, self.choices)}"
        )

    def _check_str(self, key: str, value: Any) -> str:
        return self._choice(key, value)

    def _check_strings(self, key: str, value: Any) -> tuple[str, ...]:
        if isinstance(value, str):
            value = (value,)
        if not isinstance(value, Sequence):
            raise self._refuse(key, value)
        return tuple(self._choice(key, v) for v in value)

    def _check_path(self, key: str, value: Any) -> str:
        if not isinstance(value, str | PathLike) or not str(value):
            raise self._refuse(key, value)
        return str(value)

    def _check_paths(self, key: str, value: Any) -> tuple[str, ...]:
        if isinstance(value, str | PathLike) or not isinstance(value, Sequence) or not value:
            raise self._refuse(key, value)
        return tuple(self._check_path(key, v) for v in value)

    def _check_floats(self, key: str, value: Any) -> tuple[float, ...] | str:
        if isinstance(value, str) and self.choices:
            return self._choice(key, value)
        if isinstance(value, str) or not _is_sequence(value):
            raise self._refuse(key, value)
        plain = Spec("float", "", self.section)
        try:
            return tuple(plain.check(key, v) for v in value)
        except OptionsError:
            raise self._refuse(key, value) from None

    def _check_vector(self, key: str, value: Any) -> tuple[float, float, float]:
        try:
            vector = Spec("floats", "", self.section).check(key, value)
        except OptionsError:
            raise self._refuse(key, value) from None
        if len(vector) != 3 or not any(vector):
            raise self._refuse(key, value)
        return vector

    def _check_plane(self, key: str, value: Any) -> str | tuple[float, float, float]:
        if isinstance(value, str):
            name = value.lower().replace(" ", "")
            if name not in PLANE_NAMES:
                expected = f"one of {', '.join(PLANE_NAMES)} or a normal vector x, y, z"
                raise OptionsError(key, f"must be {expected}; got {value!r}")
            return name
        return self._check_vector(key, value)


#: Named initial-guess planes (the coordinate planes, and the least-squares plane of the nodes).
PLANE_NAMES = ("best-fit", "xy", "yz", "zx", "x-y", "y-z", "z-x", "xz", "x-z")


def _is_sequence(value: Any) -> bool:
    return isinstance(value, Sequence) or (hasattr(value, "ndim") and value.ndim == 1)


def suggest(value: str, candidates: Sequence[str] = ()) -> str:
    """`` (did you mean 'x'?)`` for the closest of ``candidates``, or an empty string."""
    close = difflib.get_close_matches(value, list(candidates), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def option(
    default: Any,
    kind: str,
    help: str,
    *,
    section: str,
    choices: Sequence[str] | None = None,
    minimum: float | None = None,
    positive: bool = False,
    optional: bool | None = None,
    flags: Sequence[str] | None = None,
) -> Any:
    """A dataclass field with its :class:`Spec` (``optional`` defaults to ``default is None``)."""
    if kind not in KINDS:
        raise ValueError(f"unknown option kind {kind!r}")
    spec = Spec(
        kind,
        help,
        section,
        None if choices is None else tuple(choices),
        minimum,
        positive,
        default is None if optional is None else optional,
        None if flags is None else tuple(flags),
    )
    return field(default=default, metadata={"option": spec})


def reused(
    cls: type[Options],
    name: str,
    *,
    section: str,
    default: Any = MISSING,
    help: str | None = None,
) -> Any:
    """The option ``name`` of ``cls`` as a field of another options class, in the job-file
    table ``section``: the same kind, choices, bounds and flags, the same help unless ``help``
    says more (what the other table does with it), the same default unless ``default`` is given
    (``None`` makes it optional: "not given here")."""
    spec = cls.specs()[name]
    if default is MISSING:
        default = cls.defaults()[name]
    spec = replace(
        spec, section=section, help=help or spec.help, optional=spec.optional or default is None
    )
    return field(default=default, metadata={"option": spec})


class Options:
    """Base of the options classes: checks values on construction, reads and writes mappings.

    Subclasses are frozen dataclasses of :func:`option` fields and may add :meth:`check` for
    rules between fields.
    """

    #: Short name used in messages ("solver options").
    title: ClassVar[str] = "options"

    def __post_init__(self) -> None:
        for name, spec in self.specs().items():
            object.__setattr__(self, name, spec.check(name, getattr(self, name)))
        self.check()

    def check(self) -> None:
        """Rules between fields (raise :class:`OptionsError`)."""

    @classmethod
    def specs(cls) -> dict[str, Spec]:
        """Field name → spec, in declaration order."""
        return {f.name: f.metadata["option"] for f in fields(cls) if "option" in f.metadata}

    @classmethod
    def defaults(cls) -> dict[str, Any]:
        """Field name → default."""
        return {f.name: f.default for f in fields(cls) if f.default is not MISSING}

    def to_dict(self, *, section: str | None = None) -> dict[str, Any]:
        """The values that are set (not ``None``), tuples as lists; optionally of one section."""
        out = {}
        for name, spec in self.specs().items():
            value = getattr(self, name)
            if value is None or (section is not None and spec.section != section):
                continue
            out[name] = list(value) if isinstance(value, tuple) else value
        return out

    def replace(self, **changes: Any) -> Self:
        """A copy with some values changed (checked again)."""
        check_keys(changes, self.specs(), self.title)
        return type(self)(**{**{n: getattr(self, n) for n in self.specs()}, **changes})

    @classmethod
    def describe(cls) -> str:
        """One paragraph per option (name, default, bounds, help) for docstrings."""
        lines = []
        for name, spec in cls.specs().items():
            default = cls.defaults()[name]
            bounds = spec.bounds()
            extra = f", {bounds}" if bounds else ""
            lines.append(f"{name}: {spec.kind}, default {default!r}{extra}")
            lines.append(f"    {spec.help}")
        return "\n".join(lines)


def check_keys(data: Mapping[str, Any], known: Mapping[str, Any], what: str) -> None:
    """Refuse keys of ``data`` that are not in ``known``, suggesting the closest one."""
    for key in data:
        if key not in known:
            hint = suggest(key, list(known)) or f"; known: {', '.join(known)}"
            raise OptionsError(None, f"unknown {what} {key!r}{hint}")


def split_settings(settings: Mapping[str, Any], bases: Sequence[Options]) -> list[Options]:
    """Apply keyword ``settings`` to the options objects ``bases`` (each key to the class that
    declares it); an unknown key is an :class:`OptionsError` with a suggestion."""
    known: dict[str, int] = {}
    for index, base in enumerate(bases):
        known.update(dict.fromkeys(base.specs(), index))
    check_keys(settings, known, "option")
    out = []
    for index, base in enumerate(bases):
        mine = {k: v for k, v in settings.items() if known[k] == index}
        out.append(base.replace(**mine) if mine else base)
    return out


def takes_options(*classes: type[Options]) -> Callable[[Callable], Callable]:
    """Give a ``**settings`` function one keyword argument per option of ``classes``.

    The function's signature (for ``help()``, editors and introspection) and its docstring show
    each option with its default; the function itself receives them in ``**settings`` and turns
    them into options objects with :func:`split_settings`.
    """

    def decorate(func: Callable) -> Callable:
        signature = inspect.signature(func)
        own = [p for p in signature.parameters.values() if p.kind != p.VAR_KEYWORD]
        names = {p.name for p in own}
        added = []
        for cls in classes:
            defaults = cls.defaults()
            for name, spec in cls.specs().items():
                if name in names:  # declared by the function or an earlier class
                    continue
                names.add(name)
                added.append(
                    inspect.Parameter(
                        name,
                        inspect.Parameter.KEYWORD_ONLY,
                        default=defaults[name],
                        annotation=_ANNOTATIONS[spec.kind]
                        + (" | str" if spec.kind == "floats" and spec.choices else "")
                        + (" | None" if spec.optional else ""),
                    )
                )
        func.__signature__ = signature.replace(parameters=own + added)
        listing = "\n\n".join(cls.describe() for cls in classes)
        func.__doc__ = (func.__doc__ or "") + "\n\nOptions\n-------\n" + listing + "\n"
        return func

    return decorate


_ANNOTATIONS = {
    "bool": "bool",
    "int": "int",
    "float": "float",
    "str": "str",
    "vector": "tuple[float, float, float]",
    "plane": "str | tuple[float, float, float]",
    "floats": "tuple[float, ...]",
    "strings": "tuple[str, ...]",
    "path": "str",
    "paths": "tuple[str, ...]",
}
