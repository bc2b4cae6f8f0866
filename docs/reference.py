"""The command-line and configuration references of the docs, generated from their one source.

* :func:`cli_markdown`: every command's ``-h`` text, from the argparse parser the ``cmdragons``
  command builds (``cmdragons.cli.build_parser``) and the ``vision calibrate`` / ``vision tune``
  parsers, asked through ``cmdragons.cli.main`` as a user would.
* :func:`config_markdown`: every key of every ``configs/<concern>.yaml``, walked from the params
  dataclasses the loader parses it into (``cmdragons.runtime.settings.CONCERNS``): its type, unit (from
  the unit in its name), range or choices (from ``setting(lo=, hi=, choices=)`` or a ``Literal``),
  default (the dataclass's), and what it is (the comment beside the key in the shipped YAML file).

The docs build calls both through ``docs/hooks.py``; ``python docs/reference.py cli|config``
prints one.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import os
import sys
import typing
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any, Literal, get_args, get_origin, get_type_hints

ROOT = Path(__file__).resolve().parents[1]

# the unit a name's suffix states (the project names every quantity with its SI unit); longest first
UNITS = (
    ("_rad_s2", "rad/s²"), ("_m_s2", "m/s²"), ("_rad_s", "rad/s"), ("_m_s", "m/s"), ("_deg_s", "deg/s"),
    ("_mm_s", "mm·s"), ("_kg_m2", "kg·m²"), ("_n_s", "N·s"), ("_hz", "Hz"), ("_ms", "ms"), ("_us", "µs"),
    ("_mm", "mm"), ("_px", "px"), ("_deg", "deg"), ("_rad", "rad"), ("_kg", "kg"), ("_mb", "MB"),
    ("_bytes", "bytes"), ("_grey", "grey levels"), ("_m", "m"), ("_s", "s"), ("_n", "N"),
)  # fmt: skip


def cli_markdown() -> str:
    """Every command's help, as ``cmdragons COMMAND -h`` prints it (at 100 columns)."""
    os.environ["COLUMNS"] = "100"
    from cmdragons.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, _subparsers_type()))
    parts = ["## `cmdragons`", "", _block(parser.format_help())]
    for name, command in sub.choices.items():
        parts += [f"## `cmdragons {name}`", "", _block(command.format_help())]
        if name == "vision":
            for tool in ("calibrate", "tune"):
                parts += [f"## `cmdragons vision {tool}`", "", _block(_help(["vision", tool, "-h"]))]
    return "\n".join(parts)


def _subparsers_type() -> type:
    import argparse

    return argparse._SubParsersAction


def _help(argv: list[str]) -> str:
    from cmdragons.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.suppress(SystemExit):
        main(argv)
    return out.getvalue()


def _block(text: str) -> str:
    return "```text\n" + text.rstrip() + "\n```\n"


def config_markdown(config_dir: Path = ROOT / "configs") -> str:
    """One table per config file: every key with its type, unit, range and default."""
    from ruamel.yaml import YAML

    from cmdragons.runtime.settings import CONCERNS

    parts = []
    for concern, cls in CONCERNS.items():
        path = config_dir / f"{concern}.yaml"
        shipped = YAML().load(path.read_text(encoding="utf-8")) if path.exists() else None
        parts += [f"## `{concern}.yaml`", ""]
        head = _file_comment(path)
        if head:
            parts += [head, ""]
        parts += ["| key | type | unit | range | default | what |", "|---|---|---|---|---|---|"]
        parts += [_row(*entry) for entry in _walk(cls, shipped, "")]
        parts.append("")
    return "\n".join(parts)


def _file_comment(path: Path) -> str:
    """The comment lines a config file opens with."""
    if not path.exists():
        return ""
    lines = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("# ").rstrip())
    return " ".join(lines)


Entry = tuple[str, Any, dataclasses.Field[Any], Any, str]


def _walk(cls: type, shipped: Any, prefix: str, default_obj: Any = None) -> Iterator[Entry]:
    """(key, type, field, default, comment) of every leaf key of dataclass ``cls``, the defaults read
    from ``default_obj`` (an instance of ``cls``; default ``cls()``)."""
    hints = get_type_hints(cls)
    defaults = _defaults(cls, default_obj)
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        known = f.metadata.get("sections")
        if known is not None:  # plugin sections (a registry's): beside the concern's own keys, each as its type
            for name, section_type in known().items():
                here = shipped.get(name) if isinstance(shipped, Mapping) else None
                yield from _walk(section_type, here, f"{prefix}{name}.")
            continue
        key, tp = prefix + f.name, hints[f.name]
        here = shipped.get(f.name) if isinstance(shipped, Mapping) else None
        comment = _comment(shipped, f.name)
        inner = _dataclass_in(tp)
        if inner is not None and "source" not in f.metadata:
            if comment:
                yield key, None, f, None, comment
            yield from _walk(inner, here, key + ".", defaults.get(f.name))
            continue
        mapped = _mapping_of_dataclass(tp)
        if mapped is not None:
            default = defaults.get(f.name) or {}
            names = list(here) if isinstance(here, Mapping) else list(default)
            yield key, None, f, None, comment or "a mapping of names to sections, each as below"
            for name in names:
                sub = here.get(name) if isinstance(here, Mapping) else None
                yield from _walk(mapped, sub, f"{key}.{name}.", default.get(name))
            continue
        if get_origin(tp) in (dict, Mapping, typing.Mapping) and isinstance(here, Mapping) and here:
            default = defaults.get(f.name) or {}
            yield key, None, f, None, comment or "a mapping, each entry as below"
            for name in here:  # each entry the shipped file has, with its default
                entry = default.get(name, dataclasses.MISSING) if isinstance(default, Mapping) else dataclasses.MISSING
                yield f"{key}.{name}", get_args(tp)[1], f, entry, _comment(here, name)
            continue
        yield key, tp, f, defaults.get(f.name, dataclasses.MISSING), comment


def _defaults(cls: type, obj: Any = None) -> dict[str, Any]:
    if obj is None:
        try:
            obj = cls()
        except TypeError:  # a required field: no default object
            return {f.name: f.default for f in dataclasses.fields(cls) if f.default is not dataclasses.MISSING}
    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(cls) if f.init}


def _dataclass_in(tp: Any) -> type | None:
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return tp
    if get_origin(tp) in (typing.Union, __import__("types").UnionType):
        inner = [a for a in get_args(tp) if a is not type(None)]
        if len(inner) == 1:
            return _dataclass_in(inner[0])
    return None


def _mapping_of_dataclass(tp: Any) -> type | None:
    if get_origin(tp) in (dict, Mapping, typing.Mapping):
        args = get_args(tp)
        if len(args) == 2:
            return _dataclass_in(args[1])
    return None


def _comment(shipped: Any, name: str) -> str:
    items = getattr(getattr(shipped, "ca", None), "items", {})
    token = items.get(name, [None, None, None])[2] if items else None
    if token is None:
        return ""
    lines = token.value.splitlines()
    kept = [lines[0]]
    for line in lines[1:]:  # the lines that go on at the first one's column; a block below is the next key's
        if line.find("#") != token.column or line[: token.column].strip():
            break
        kept.append(line)
    return " ".join(line.strip().lstrip("#").strip() for line in kept).strip()


def _row(key: str, tp: Any, f: dataclasses.Field[Any], default: Any, comment: str) -> str:
    if tp is None:  # a section's own line
        return f"| **`{key}`** | section | | | | {_cell(comment)} |"
    source = f.metadata.get("source")
    what = f"set as `{source}` (not in this file)" + (f"; {comment}" if comment else "") if source else comment
    shown = "(required)" if default is dataclasses.MISSING else f"`{_value(default)}`"
    return f"| `{key}` | {_type(tp)} | {_unit(f.name)} | {_cell(_range(f, tp))} | {_cell(shown)} | {_cell(what)} |"


def _unit(name: str) -> str:
    return next((unit for suffix, unit in UNITS if name.endswith(suffix)), "")


def _range(f: dataclasses.Field[Any], tp: Any) -> str:
    lo, hi, choices = f.metadata.get("lo"), f.metadata.get("hi"), f.metadata.get("choices")
    if callable(choices):  # choices that follow a registry (a plugin's name)
        choices = tuple(choices())
    if choices is not None:
        return " | ".join(f"`{c}`" for c in choices)
    literal = _literal(tp)
    if literal:
        return " | ".join(f"`{c}`" for c in literal)
    if lo is not None and hi is not None:
        return f"{lo} to {hi}"
    if lo is not None:
        return f"≥ {lo}"
    if hi is not None:
        return f"≤ {hi}"
    return ""


def _literal(tp: Any) -> tuple[Any, ...]:
    if get_origin(tp) is Literal:
        return get_args(tp)
    if get_origin(tp) in (typing.Union, __import__("types").UnionType):
        return tuple(v for a in get_args(tp) for v in _literal(a))
    return ()


def _type(tp: Any) -> str:
    if tp in (float, int, bool, str):
        return {float: "number", int: "integer", bool: "true/false", str: "text"}[tp]
    if get_origin(tp) is Literal:
        return "choice"
    if get_origin(tp) is tuple:
        return "list"
    if get_origin(tp) in (dict, Mapping, typing.Mapping):
        return "mapping"
    if get_origin(tp) in (typing.Union, __import__("types").UnionType):
        return " or ".join(_type(a) if a is not type(None) else "null" for a in get_args(tp))
    if dataclasses.is_dataclass(tp):
        return "section"
    return "any"


def _value(value: Any) -> str:
    from cmdragons.config import to_plain

    plain = to_plain(value)
    if isinstance(plain, bool):
        return "true" if plain else "false"
    if plain is None:
        return "null"
    if isinstance(plain, float) and plain.is_integer() and abs(plain) < 1e15:
        return f"{plain:.1f}"
    text = str(plain).replace("'", "")
    return text if len(text) <= 60 else text[:57] + "..."


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    print(cli_markdown() if sys.argv[1:] == ["cli"] else config_markdown())
