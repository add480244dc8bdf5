"""Checks of single values read from a recording's files (manifest, scenario, JSON lines).

Each check returns the value in the type the TDM uses, or raises :class:`tdm.errors.RecordingError`
naming the file, the place (a key path such as ``tdm.update_rate_hz`` or ``line 12``) and what is
wrong. Numbers are finite and inside stated bounds, so no size the TDM derives from them (epochs,
periods, array lengths) can be absurd.
"""

from __future__ import annotations

import math
from pathlib import Path

from tdm.errors import RecordingError

__all__ = ["describe", "mapping", "number", "integer", "boolean", "text", "optional"]


def describe(value: object) -> str:
    """A short description of a value for an error message: its type and, when short, its text."""
    kind = {dict: "a mapping", list: "a list", str: "a string", bool: "a boolean", type(None): "null"}.get(
        type(value), type(value).__name__)
    shown = repr(value)
    return f"{kind} {shown}" if len(shown) <= 40 and not isinstance(value, (dict, list)) else kind


def mapping(value: object, file: Path | str, where: str) -> dict:
    """``value`` if it is a mapping (a JSON object, a YAML mapping), else a RecordingError."""
    if not isinstance(value, dict):
        raise RecordingError(str(file), where, f"must be a mapping, not {describe(value)}")
    return value


def number(value: object, file: Path | str, where: str, low: float | None = None, high: float | None = None,
           low_open: bool = False, unit: str = "") -> float:
    """A finite real number within ``[low, high]`` (``(low, high]`` with ``low_open``).

    Parameters
    ----------
    value : object
        The parsed value (JSON or YAML); booleans and strings are refused.
    file, where : Path or str, str
        Named in the error.
    low, high : float, optional
        Bounds (inclusive unless ``low_open``).
    unit : str
        Appended to the bounds in the message (``" s"``, ``" Hz"``).

    Returns
    -------
    float
    """
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise RecordingError(str(file), where, f"must be a number, not {describe(value)}")
    x = float(value)
    if not math.isfinite(x):
        raise RecordingError(str(file), where, f"must be a finite number, not {value!r}")
    if low is not None and (x <= low if low_open else x < low):
        raise RecordingError(str(file), where, f"{value!r} must be {'>' if low_open else '>='} {low:g}{unit}")
    if high is not None and x > high:
        raise RecordingError(str(file), where, f"{value!r} is more than the largest accepted, {high:g}{unit}")
    return x


def integer(value: object, file: Path | str, where: str, low: int | None = None, high: int | None = None) -> int:
    """A whole number (an int, or a float with no fraction) within ``[low, high]``."""
    x = number(value, file, where, low, high)
    if x != math.floor(x):
        raise RecordingError(str(file), where, f"must be a whole number, not {value!r}")
    return int(x)


def boolean(value: object, file: Path | str, where: str) -> bool:
    """``true`` or ``false``."""
    if not isinstance(value, bool):
        raise RecordingError(str(file), where, f"must be true or false, not {describe(value)}")
    return value


def text(value: object, file: Path | str, where: str) -> str:
    """A string."""
    if not isinstance(value, str):
        raise RecordingError(str(file), where, f"must be a string, not {describe(value)}")
    return value


def optional(table: dict, key: str, check, file: Path | str, prefix: str = "", **bounds):
    """``check(table[key], file, prefix + key, **bounds)`` when the key is present and not null, else None."""
    value = table.get(key)
    return None if value is None else check(value, file, f"{prefix}{key}", **bounds)
