"""YAML configuration -> frozen, typed dataclasses.

Every tunable number of the system lives in ``configs/<concern>.yaml``. Each concern is parsed
into a frozen dataclass declared beside the code that uses it. This module holds only the
generic machinery, so it imports nothing else of the project:

* :func:`load_yaml` reads one file and reports a missing file or malformed YAML (with its line);
* :func:`parse` turns a mapping into a dataclass, checking unknown keys, types, ranges and choices,
  and naming the file, the key and what is allowed when something is wrong;
* :func:`apply_override` applies one ``--set concern.key.path=value`` to the raw mappings.

Ranges and choices are declared on the dataclass fields with :func:`setting`::

    @dataclass(frozen=True)
    class MotorParams:
        max_speed_m_s: float = setting(3.0, lo=0.0, hi=10.0)

Choices may be a function that names them when asked (a registry that plugins join), and a
concern may hold plugin sections beside its own keys (:func:`sections`): each plugin's section is
parsed into the type it declares, with the same errors.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import math
import types
import typing
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal, TypeVar, Union, get_args, get_origin, get_type_hints

import yaml

# libyaml's parser where PyYAML was built with it: the same documents, about ten times faster to read
# (every command and test reads the whole configs/ at start)
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

__all__ = [
    "ConfigError",
    "FrozenMap",
    "Validated",
    "apply_override",
    "check_ranges",
    "default_config_dir",
    "derived",
    "load_yaml",
    "override_derived",
    "parse",
    "resolve_derived",
    "sections",
    "setting",
    "to_plain",
]

T = TypeVar("T")
K = TypeVar("K")
V = TypeVar("V")


class FrozenMap(Mapping[K, V]):
    """A read-only mapping for config values: hashable, comparable with dicts, and picklable
    (``types.MappingProxyType`` is not, and settings cross process boundaries)."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[K, V] | None = None) -> None:
        self._data: dict[K, V] = dict(data or {})

    def __getitem__(self, key: K) -> V:
        return self._data[key]

    def __iter__(self) -> typing.Iterator[K]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __hash__(self) -> int:
        return hash(tuple(self._data.items()))

    def __repr__(self) -> str:
        return f"FrozenMap({self._data!r})"

    def __reduce__(self) -> tuple[Any, ...]:
        return (FrozenMap, (self._data,))


class ConfigError(ValueError):
    """A configuration problem, naming the file, the key and what is allowed."""

    def __init__(self, file: str | Path, key: str, message: str) -> None:
        self.file = str(file)
        self.key = key
        self.message = message
        where = f"{self.file}: {key}" if key else self.file
        super().__init__(f"{where}: {message}")


def setting(
    default: Any = dataclasses.MISSING,
    *,
    lo: float | None = None,
    hi: float | None = None,
    choices: tuple[Any, ...] | typing.Callable[[], typing.Iterable[Any]] | None = None,
    default_factory: Any = dataclasses.MISSING,
) -> Any:
    """A dataclass field with an allowed closed range ``[lo, hi]`` or a set of choices (or a function
    that names them when a value is checked: the names of a registry)."""
    meta = {"lo": lo, "hi": hi, "choices": choices}
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def derived(source: str, default: Any, *, lo: float | None = None, hi: float | None = None) -> Any:
    """A field whose value is configured once, elsewhere: ``source`` (``concern.key.path``) gives
    it when the settings are loaded (:func:`resolve_derived`), and a YAML key for it is refused with
    an error naming the source. Built in code, it holds what is given (default ``default``), checked
    against ``[lo, hi]`` like any :func:`setting`."""
    return dataclasses.field(default=default, metadata={"source": source, "lo": lo, "hi": hi, "choices": None})


def sections(known: typing.Callable[[], Mapping[str, type]]) -> Any:
    """A field that holds plugin sections: the mapping's keys that ``known()`` names (a registry's
    sections, asked when the mapping is parsed or the object built), each parsed into its type; a
    section left out takes its type's defaults. In YAML the sections sit beside the concern's own
    keys (not under the field's name); any other key is an unknown key. The value is a
    :class:`FrozenMap` section name -> params, in ``known()``'s order."""

    def defaults() -> FrozenMap[str, Any]:
        return FrozenMap({name: tp() for name, tp in known().items()})

    return dataclasses.field(default_factory=defaults, metadata={"sections": known, "lo": None, "hi": None,
                                                                 "choices": None})


def resolve_derived(obj: T, lookup: typing.Callable[[str], Any]) -> T:
    """``obj`` with every :func:`derived` field (in nested dataclasses and mappings too) set to
    ``lookup(source)``."""
    return _replace_derived(obj, lambda source, _value: lookup(source))


def override_derived(obj: T, values: Mapping[str, Any]) -> T:
    """``obj`` with the :func:`derived` fields whose source ``values`` names (``field.ball.acc_roll_m_s2``)
    set to its value, the others as they are: facts measured at run time in place of the configured ones."""
    return _replace_derived(obj, lambda source, value: values.get(source, value))


def _replace_derived(obj: T, new_value: typing.Callable[[str, Any], Any]) -> T:
    if isinstance(obj, Mapping):
        return type(obj)({k: _replace_derived(v, new_value) for k, v in obj.items()})  # type: ignore[call-arg]
    if not (dataclasses.is_dataclass(obj) and not isinstance(obj, type)):
        return obj
    changes: dict[str, Any] = {}
    for f in dataclasses.fields(obj):
        if not f.init:
            continue
        value = getattr(obj, f.name)
        source = f.metadata.get("source")
        new = new_value(source, value) if source is not None else _replace_derived(value, new_value)
        if new is not value:
            changes[f.name] = new
    return dataclasses.replace(obj, **changes) if changes else obj


def default_config_dir() -> Path:
    """``./configs`` when the working directory has one, else the configs beside the package."""
    here = Path.cwd() / "configs"
    if here.is_dir():
        return here
    return Path(__file__).resolve().parent.parent / "configs"


def load_yaml(path: str | Path) -> dict[str, Any]:
    """Read one YAML mapping; a missing file or malformed YAML raises :class:`ConfigError`."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(path, "", "file not found")
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_YAML_LOADER)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        line = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        raise ConfigError(path, "", f"malformed YAML at {line}{exc.problem}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(path, "", f"malformed YAML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(path, "", f"not UTF-8 text: {exc}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(path, "", f"the top level must be a mapping of keys, not {type(data).__name__}")
    return data


def apply_override(raw: dict[str, dict[str, Any]], assignment: str) -> None:
    """Apply ``concern.key.path=value`` to the raw mappings of all concerns, in place.

    The value is read as a YAML scalar or flow collection (``3``, ``true``, ``[1, 2]``).
    """
    origin = f"--set {assignment}"
    if "=" not in assignment:
        raise ConfigError(origin, "", "expected concern.key.path=value")
    path, _, text = assignment.partition("=")
    parts = [p for p in path.strip().split(".") if p]
    if len(parts) < 2:
        raise ConfigError(origin, path, "expected at least concern.key (for example sim.physics.substeps=8)")
    concern = parts[0]
    if concern not in raw:
        raise ConfigError(origin, concern, f"unknown concern; allowed: {', '.join(sorted(raw))}")
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        problem = getattr(exc, "problem", None) or type(exc).__name__
        raise ConfigError(origin, path, f"value {text!r} is not valid YAML ({problem}); write a number, true/false, "
                                        "a word, or a list such as [1, 2]") from None
    node: Any = raw[concern]
    for i, key in enumerate(parts[1:-1], start=1):
        if isinstance(node, list):
            node = _list_item(node, key, origin, ".".join(parts[: i + 1]))
            continue
        if not isinstance(node, dict):
            raise ConfigError(origin, ".".join(parts[: i + 1]), "cannot descend into a scalar value")
        node = node.setdefault(key, {})
    last = parts[-1]
    if isinstance(node, list):
        index = int(last) if last.lstrip("-").isdigit() else None
        if index is None or not -len(node) <= index < len(node):
            raise ConfigError(origin, path, f"list index out of range 0..{len(node) - 1}")
        node[index] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise ConfigError(origin, path, "cannot descend into a scalar value")


def _list_item(node: list[Any], key: str, origin: str, where: str) -> Any:
    if not key.lstrip("-").isdigit() or not -len(node) <= int(key) < len(node):
        raise ConfigError(origin, where, f"list index out of range 0..{len(node) - 1}")
    return node[int(key)]


def parse(cls: type[T], data: Any, *, file: str | Path, key: str = "") -> T:
    """Build dataclass ``cls`` from ``data``; every problem raises :class:`ConfigError`.

    Missing keys take the dataclass defaults; unknown keys, wrong types, values out of range or
    outside the declared choices are errors. ``__post_init__`` may raise ``ValueError`` for checks
    that involve several fields; its message is reported with the file and key.
    """
    return typing.cast(T, _convert(cls, data, str(file), key))


def to_plain(obj: Any) -> Any:
    """A dataclass (tree) as plain dicts, lists and scalars, ready for YAML or JSON."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        out: dict[str, Any] = {}
        for f in dataclasses.fields(obj):
            value = to_plain(getattr(obj, f.name))
            if "sections" in f.metadata:
                out.update(value)  # beside the concern's own keys, as in its YAML
            else:
                out[f.name] = value
        return out
    if isinstance(obj, Mapping):
        return {str(k): to_plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_plain(v) for v in obj]
    return obj


def _join(key: str, sub: str | int) -> str:
    if isinstance(sub, int):
        return f"{key}[{sub}]"
    return f"{key}.{sub}" if key else sub


def _convert(tp: Any, value: Any, file: str, key: str) -> Any:
    origin = get_origin(tp)
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return _convert_dataclass(tp, value, file, key)
    if tp is Any:
        return value
    if origin is Literal:
        allowed = get_args(tp)
        if value not in allowed or isinstance(value, bool) != isinstance(allowed[0], bool):
            raise ConfigError(file, key, f"{value!r} is not allowed; allowed: {', '.join(map(repr, allowed))}")
        return value
    if origin in (Union, types.UnionType):
        args = get_args(tp)
        if value is None and type(None) in args:
            return None
        errors = []
        for arg in args:
            if arg is type(None):
                continue
            try:
                return _convert(arg, value, file, key)
            except ConfigError as exc:
                errors.append(exc.message)
        raise ConfigError(file, key, " or ".join(errors))
    if origin is tuple:
        args = get_args(tp)
        if not isinstance(value, list | tuple):
            raise ConfigError(file, key, f"expected a list, got {value!r}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(args[0], v, file, _join(key, i)) for i, v in enumerate(value))
        if len(value) != len(args):
            raise ConfigError(file, key, f"expected a list of {len(args)} values, got {len(value)}")
        return tuple(_convert(a, v, file, _join(key, i)) for i, (a, v) in enumerate(zip(args, value, strict=True)))
    if origin in (dict, Mapping):
        key_t, val_t = get_args(tp)
        if not isinstance(value, dict):
            raise ConfigError(file, key, f"expected a mapping, got {value!r}")
        out = {}
        for k, v in value.items():
            out[_convert(key_t, k, file, _join(key, str(k)))] = _convert(val_t, v, file, _join(key, str(k)))
        return FrozenMap(out)
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(file, key, f"expected true or false, got {value!r}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(file, key, f"expected an integer, got {value!r}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(file, key, f"expected a number, got {value!r}")
        if not math.isfinite(value):
            raise ConfigError(file, key, f"expected a finite number, got {value!r}")
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(file, key, f"expected a string, got {value!r}")
        return value
    raise TypeError(f"config type {tp!r} at {key} is not supported")


@functools.cache
def _type_hints(cls: type) -> dict[str, Any]:
    """A params class's field types, resolved once (the string annotations compile on each call)."""
    return get_type_hints(cls)


def _convert_dataclass(cls: type, value: Any, file: str, key: str) -> Any:
    if isinstance(value, cls):
        return value
    if value is None:
        value = {}
    if not isinstance(value, dict):
        raise ConfigError(file, key, f"expected a mapping, got {value!r}")
    hints = _type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    plugins = next((f for f in fields.values() if "sections" in f.metadata), None)
    known: Mapping[str, type] = plugins.metadata["sections"]() if plugins is not None else {}
    own = [name for name, f in fields.items() if f is not plugins]
    for k in value:
        source = fields[k].metadata.get("source") if k in fields else None
        if source is not None:
            raise ConfigError(file, _join(key, str(k)), f"configured once, as {source}: set that instead")
    unknown = [k for k in value if k not in own and k not in known]
    if unknown:
        allowed = [*own, *known]
        close = difflib.get_close_matches(str(unknown[0]), allowed, n=1)
        hint = f"; did you mean {close[0]}?" if close else ""
        raise ConfigError(
            file, _join(key, str(unknown[0])), f"unknown key; allowed keys: {', '.join(sorted(allowed))}{hint}"
        )
    kwargs = {}
    for name, f in fields.items():
        sub = _join(key, name)
        if f is plugins:
            kwargs[name] = FrozenMap({s: _convert(tp, value[s], file, _join(key, s)) if s in value else tp()
                                      for s, tp in known.items()})
            continue
        if name not in value:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise ConfigError(file, sub, "missing required key")
            continue
        converted = _convert(hints[name], value[name], file, sub)
        _check_limits(f, converted, file, sub)
        kwargs[name] = converted
    try:
        return cls(**kwargs)
    except ConfigError:
        raise
    except (ValueError, TypeError) as exc:
        raise ConfigError(file, key, str(exc)) from None


def check_ranges(obj: Any) -> None:
    """Check every :func:`setting` field of dataclass ``obj`` against its range and choices;
    raises ``ValueError`` naming the field (the loader adds the file)."""
    for f in dataclasses.fields(obj):
        try:
            _check_limits(f, getattr(obj, f.name), "", f.name)
        except ConfigError as exc:
            raise ValueError(f"{exc.key}: {exc.message}") from None


class Validated:
    """Mixin for parameter dataclasses: ranges are checked however the object is built."""

    def __post_init__(self) -> None:
        check_ranges(self)


def _check_limits(f: dataclasses.Field[Any], value: Any, file: str, key: str) -> None:
    lo, hi, choices = f.metadata.get("lo"), f.metadata.get("hi"), f.metadata.get("choices")
    if callable(choices):
        choices = tuple(choices())
    items = value if isinstance(value, tuple) else (value,)
    for i, item in enumerate(items):
        where = _join(key, i) if isinstance(value, tuple) else key
        if choices is not None and item not in choices:
            raise ConfigError(file, where, f"{item!r} is not allowed; allowed: {', '.join(map(repr, choices))}")
        if isinstance(item, int | float) and not isinstance(item, bool):
            if (lo is not None and item < lo) or (hi is not None and item > hi):
                raise ConfigError(file, where, f"{item!r} is out of range; allowed: {_range(lo, hi)}")


def _range(lo: float | None, hi: float | None) -> str:
    if lo is not None and hi is not None:
        return f"{lo} to {hi}"
    if lo is not None:
        return f">= {lo}"
    return f"<= {hi}"
