"""Strict conversion of parsed YAML into typed, frozen dataclasses.

A schema is a dataclass whose fields carry metadata made by :func:`param`:
a documentation line, a unit-bearing name, bounds and an optional check.
:func:`build` walks the YAML tree, rejects unknown keys, wrong types, NaN/inf,
numbers that float32 turns into 0, a subnormal or inf, out-of-range values, times no
``datetime`` holds and symlink loops in paths, and raises :class:`raysim.errors.InputError` naming the
key path (``ships[1].ais.mmsi``). :func:`to_plain` turns a built object back
into plain YAML-able data, and :func:`describe` lists every field with its
default for the documentation.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import errno
import math
import types
import typing
from pathlib import Path
from typing import Any, Callable, Literal, get_args, get_origin

from raysim.errors import InputError

DERIVED = "derived"  # doc marker for defaults computed from other fields

_MISSING = dataclasses.MISSING

#: Smallest normal and largest float32 (``numpy.finfo(numpy.float32)``): every number of a schema must
#: lie between them (or be 0), since meshes, rays and sweeps are float32.
FLOAT32_TINY = 1.1754943508222875e-38
FLOAT32_MAX = 3.4028234663852886e38


def param(
    default: Any = _MISSING,
    *,
    doc: str,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    min_items: int | None = None,
    check: Callable[[Any], str | None] | None = None,
    default_doc: str | None = None,
    default_factory: Callable[[], Any] | None = None,
    aliases: tuple[str, ...] = (),
) -> Any:
    """A schema field.

    Parameters
    ----------
    default : optional
        Default value; leave out for a required key. ``None`` with ``default_doc``
        marks a default derived from other fields at resolve time.
    doc : str
        One-line description (goes into docs/scenario.md).
    ge, gt, le, lt : float, optional
        Inclusive / exclusive bounds for numbers (and for each number in a list).
    min_items : int, optional
        Minimum length of a list.
    check : callable, optional
        ``check(value) -> message or None`` for anything else.
    default_doc : str, optional
        How the default is derived, when it is not a constant.
    aliases : tuple of str, optional
        Other names the key may be given by (e.g. the thesis's own parameter names).
    """
    meta = dict(doc=doc, ge=ge, gt=gt, le=le, lt=lt, min_items=min_items, check=check, default_doc=default_doc,
                aliases=tuple(aliases))
    if default_factory is not None:
        return dataclasses.field(default_factory=default_factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


class Context:
    """Where the YAML came from: the file (for error messages) and its folder (for relative paths)."""

    def __init__(self, file: str | Path):
        self.file = str(file)
        self.base_dir = Path(file).resolve().parent

    def fail(self, where: str, what: str) -> typing.NoReturn:
        raise InputError(self.file, where or "(top level)", what)


def _type_name(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return f"the number {value!r}"
    if isinstance(value, str):
        return f"the string {value!r}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return type(value).__name__


def _child(path: str, key: str | int) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def _check_number(value: float, meta: dict, ctx: Context, path: str) -> None:
    if not math.isfinite(value):
        ctx.fail(path, f"must be a finite number, got {value!r}")
    for key, ok, word in (
        ("ge", lambda v, b: v >= b, ">="),
        ("gt", lambda v, b: v > b, ">"),
        ("le", lambda v, b: v <= b, "<="),
        ("lt", lambda v, b: v < b, "<"),
    ):
        bound = meta.get(key)
        if bound is not None and not ok(value, bound):
            ctx.fail(path, f"must be {word} {bound:g}, got {value:g}")


def _exponent_hint(value: Any) -> str:
    """For ``1e-3`` (a string to YAML 1.1, which wants ``1.0e-3``): how to write it as a number."""
    if not isinstance(value, str):
        return ""
    try:
        number = float(value)
    except ValueError:
        return ""
    if "e" in value.lower() and "." not in value and math.isfinite(number):
        mantissa, exponent = value.lower().split("e", 1)
        return f" (YAML reads {value} as text: write {mantissa}.0e{exponent})"
    return ""


def _check_float32(value: float, ctx: Context, path: str) -> None:
    """Refuse a number that float32, the renderer's geometry type, turns into 0, a subnormal or inf."""
    if value != 0.0 and abs(value) < FLOAT32_TINY:
        ctx.fail(path, f"{value:g} is below {FLOAT32_TINY:.4g}, the smallest normal float32: it would collapse to "
                       "zero (or lose its precision) in the renderer's float32 arithmetic")
    if abs(value) > FLOAT32_MAX:
        ctx.fail(path, f"{value:g} is beyond {FLOAT32_MAX:.4g}, the largest float32")


def _to_float(value: Any, meta: dict, ctx: Context, path: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        ctx.fail(path, f"must be a number, got {_type_name(value)}{_exponent_hint(value)}")
    try:
        number = float(value)
    except OverflowError:  # an integer beyond any float
        ctx.fail(path, f"must be a finite number, got an integer of {len(str(abs(value)))} digits")
    _check_number(number, meta, ctx, path)
    _check_float32(number, ctx, path)
    return number


def _to_path(value: Any, ctx: Context, path: str) -> Path:
    """The absolute path of a path key, relative to the YAML file's folder; a symlink loop is refused."""
    if not isinstance(value, str) or not value.strip():
        ctx.fail(path, f"must be a file path, got {_type_name(value)}")
    try:
        return (ctx.base_dir / value).resolve()
    except (RuntimeError, OSError, ValueError) as exc:  # RuntimeError: a symlink loop (Python < 3.13)
        loop = isinstance(exc, RuntimeError) or getattr(exc, "errno", None) == errno.ELOOP
        ctx.fail(path, f"symlink loop: {value} leads back to itself" if loop else f"not a usable path: {value!r}")


def _to_datetime(value: Any, ctx: Context, path: str) -> dt.datetime:
    """An aware UTC time from an ISO 8601 string or a YAML timestamp (no zone: UTC)."""
    if isinstance(value, str):
        try:
            value = dt.datetime.fromisoformat(value.replace("Z", "+00:00"))
        except ValueError:
            ctx.fail(path, f"must be an ISO 8601 UTC time such as 2017-06-01T12:00:00Z, got {value!r}")
    if not isinstance(value, dt.datetime):
        ctx.fail(path, f"must be an ISO 8601 UTC time such as 2017-06-01T12:00:00Z, got {_type_name(value)}")
    if value.tzinfo is None:
        value = value.replace(tzinfo=dt.timezone.utc)
    try:
        return value.astimezone(dt.timezone.utc)
    except OverflowError:  # 0001-01-01T00:30:00+01:00 is before year 1 in UTC
        ctx.fail(path, f"{value.isoformat()} is before 0001-01-01T00:00:00Z, the first time a datetime holds")


def _convert(tp: Any, value: Any, meta: dict, ctx: Context, path: str) -> Any:
    origin = get_origin(tp)
    args = get_args(tp)
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        inner = [a for a in args if a is not type(None)]
        if value is None:
            ctx.fail(path, "must not be null")
        if len(inner) == 1:
            return _convert(inner[0], value, meta, ctx, path)
        errors = []
        for candidate in inner:
            try:
                return _convert(candidate, value, meta, ctx, path)
            except InputError as exc:
                errors.append(exc.what)
        ctx.fail(path, errors[-1])
    if origin is Literal:
        if value not in args or (isinstance(value, bool) and not any(isinstance(a, bool) for a in args)):
            allowed = ", ".join(repr(a) for a in args)
            ctx.fail(path, f"must be one of {allowed}, got {_type_name(value)}")
        return value
    if dataclasses.is_dataclass(tp):
        return build(tp, value, ctx, path)
    if origin in (list, tuple):
        if not isinstance(value, list):
            ctx.fail(path, f"must be a list, got {_type_name(value)}")
        if origin is tuple and args and args[-1] is not Ellipsis:
            if len(value) != len(args):
                ctx.fail(path, f"must be a list of {len(args)} items, got {len(value)}")
            items = [_convert(a, v, meta, ctx, _child(path, i)) for i, (a, v) in enumerate(zip(args, value))]
        else:
            item_tp = args[0] if args else Any
            if meta.get("min_items") is not None and len(value) < meta["min_items"]:
                ctx.fail(path, f"must have at least {meta['min_items']} item(s), got {len(value)}")
            items = [_convert(item_tp, v, meta, ctx, _child(path, i)) for i, v in enumerate(value)]
        return tuple(items)
    if tp is bool:
        if not isinstance(value, bool):
            ctx.fail(path, f"must be true or false, got {_type_name(value)}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            ctx.fail(path, f"must be an integer, got {_type_name(value)}")
        _check_number(value, meta, ctx, path)
        return value
    if tp is float:
        return _to_float(value, meta, ctx, path)
    if tp is str:
        if not isinstance(value, str) or not value.strip():
            ctx.fail(path, f"must be a non-empty string, got {_type_name(value)}")
        return value
    if tp is Path:
        return _to_path(value, ctx, path)
    if tp is dt.datetime:
        return _to_datetime(value, ctx, path)
    if tp is Any:
        return value
    raise TypeError(f"schema type {tp!r} at {path} is not supported")  # a bug in a schema, not bad input


def build(cls: type, data: Any, ctx: Context, path: str = "") -> Any:
    """Build the dataclass ``cls`` from parsed YAML ``data``, strictly.

    Raises
    ------
    InputError
        Naming ``ctx.file``, the key path and what is wrong.
    """
    if data is None:
        data = {}
    if not isinstance(data, dict):
        ctx.fail(path, f"must be a mapping of keys to values, got {_type_name(data)}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    alias_of = {a: f.name for f in fields.values() for a in f.metadata.get("aliases", ())}
    if alias_of and any(key in alias_of for key in data):
        renamed, given_as = {}, {}
        for key, value in data.items():
            name = alias_of.get(key, key)
            if name in renamed:
                ctx.fail(_child(path, str(key)), f"given twice (as {given_as[name]} and as {key})")
            renamed[name], given_as[name] = value, key
        data = renamed
    for key in data:
        if key not in fields:
            allowed = ", ".join(fields)
            ctx.fail(_child(path, str(key)), f"unknown key (allowed here: {allowed})")
    values = {}
    for name, f in fields.items():
        sub = _child(path, name)
        if name in data:
            values[name] = _convert(hints[name], data[name], dict(f.metadata), ctx, sub)
            check = f.metadata.get("check")
            if check is not None and values[name] is not None:
                message = check(values[name])
                if message:
                    ctx.fail(sub, message)
        elif f.default is _MISSING and f.default_factory is _MISSING:
            ctx.fail(sub, "required key is missing")
    return cls(**values)


def to_plain(obj: Any) -> Any:
    """Plain YAML-able data (dicts, lists, numbers, strings) from a built object."""
    if dataclasses.is_dataclass(obj):
        return {f.name: to_plain(getattr(obj, f.name)) for f in dataclasses.fields(obj) if f.init}
    if isinstance(obj, (list, tuple)):
        return [to_plain(v) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, dt.datetime):
        return obj.astimezone(dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ").replace(".000000Z", "Z")
    if isinstance(obj, float) and obj.is_integer() and abs(obj) < 1e15:
        return obj  # keep floats as floats (YAML writes 10.0)
    return obj


def describe(cls: type, path: str = "") -> list[tuple[str, str, str, str]]:
    """Rows ``(key path, type, default, doc)`` for every field of a schema, recursively."""
    rows = []
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        sub = _child(path, f.name)
        tp = hints[f.name]
        inner = [a for a in get_args(tp) if a is not type(None)] if get_origin(tp) in (typing.Union, types.UnionType) else [tp]
        if f.metadata.get("default_doc"):
            default = f.metadata["default_doc"]
        elif f.default is not _MISSING:
            default = "null" if f.default is None else repr(to_plain(f.default))
        elif f.default_factory is not _MISSING:
            value = f.default_factory()
            default = "(see below)" if dataclasses.is_dataclass(value) else repr(to_plain(value))
        else:
            default = "required"
        doc = f.metadata.get("doc", "")
        if f.metadata.get("aliases"):
            doc += " (also as " + ", ".join(f"`{a}`" for a in f.metadata["aliases"]) + ")"
        rows.append((sub, _describe_type(tp), default, doc))
        for candidate in inner:
            if dataclasses.is_dataclass(candidate):
                rows.extend(describe(candidate, sub))
            elif get_origin(candidate) in (list, tuple):
                item = get_args(candidate)[0] if get_args(candidate) else None
                if item is not None and dataclasses.is_dataclass(item):
                    rows.extend(describe(item, sub + "[]"))
    return rows


def _describe_type(tp: Any) -> str:
    origin = get_origin(tp)
    args = get_args(tp)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(_describe_type(a) for a in args)
    if origin is Literal:
        return " / ".join(repr(a) for a in args)
    if origin in (list, tuple):
        if origin is tuple and args and args[-1] is not Ellipsis:
            return "[" + ", ".join(_describe_type(a) for a in args) + "]"
        return "list of " + _describe_type(args[0]) if args else "list"
    if dataclasses.is_dataclass(tp):
        return "mapping"
    if tp is type(None):
        return "null"
    if tp is Path:
        return "path"
    if tp is dt.datetime:
        return "UTC time"
    return getattr(tp, "__name__", str(tp))
