"""``scenario.yaml``: the values the TDM takes from the resolved scenario, each checked.

The file must be UTF-8 YAML holding a mapping. Of its keys only those the TDM uses are checked
(the table :data:`CHECKED`, key path -> kind and bounds): each is absent, null, or a finite number
within its bounds (whole for counts), so a rate of NaN, 0 or 1e9 Hz, a mount of ``"high"`` or a
spoke count of 2048.5 is an error naming its key path, never a division by zero or an allocation
sized by a wild number. Sections the TDM reads (``tdm``, ``sensors``, ``sensors.<name>``, their
``mount`` and ``own_ship``) must be mappings when present. A key in one of them that is not one the TDM
reads but is within a typo of one the section lacks (``update_rate_hzz`` where ``update_rate_hz`` is
missing: :func:`difflib.get_close_matches`, :data:`MISSPELT_RATIO`) is an error: a hand-edited recording would
otherwise run on the default. The other keys raysim writes there are not the TDM's to judge.
"""

from __future__ import annotations

import difflib
from pathlib import Path

import yaml

from groundfloor.frames import MOUNT_KEYS
from groundfloor.recording import SCENARIO
from tdm.errors import RecordingError
from tdm.recording import values
from tdm.recording.files import decode_utf8, read_bytes

__all__ = ["read_scenario", "check_scenario", "nav_settings", "CHECKED", "MAX_UPDATE_RATE_HZ"]

#: Highest accepted TDM output rate, Hz (raysim's scenarios allow 50).
MAX_UPDATE_RATE_HZ = 100.0
#: A resolved scenario is a few kB (the world's meshes are separate files).
MAX_SCENARIO_BYTES = 16 << 20
_MOUNT = {k: ("number", -1000.0, 1000.0) if k.endswith("_m") else ("number", -360.0, 360.0) for k in MOUNT_KEYS}

#: Key path -> (kind, low, high); "rate" is a number > low, "number" one >= low, "count" a whole number.
CHECKED: dict[str, tuple[str, float, float]] = {
    "tdm.update_rate_hz": ("rate", 0.0, MAX_UPDATE_RATE_HZ),
    "own_ship.length_m": ("rate", 0.0, 10_000.0),
    "own_ship.beam_m": ("rate", 0.0, 10_000.0),
    "sensors.lidar.rotation_hz": ("rate", 0.0, 100.0),
    "sensors.lidar.range_min_m": ("number", 0.0, 10_000.0),
    "sensors.lidar.range_max_m": ("rate", 0.0, 10_000.0),
    "sensors.lidar.beam_divergence_mrad": ("number", 0.0, 1000.0),
    "sensors.radar.rpm": ("rate", 0.0, 600.0),
    "sensors.radar.range_m": ("rate", 0.0, 1.0e6),
    "sensors.radar.spokes": ("count", 1, 65_536),
    "sensors.radar.samples": ("count", 1, 65_536),
    "sensors.radar.beam_az_deg": ("rate", 0.0, 360.0),
    "sensors.radar.blanking_m": ("number", 0.0, 1.0e6),
    "sensors.ais.range_m": ("rate", 0.0, 1.0e7),
    "sensors.nav.position_noise_m": ("number", 0.0, 1.0e6),
    "sensors.nav.position_bias_m": ("number", 0.0, 1.0e6),
    "sensors.nav.heading_noise_deg": ("number", 0.0, 360.0),
    "sensors.nav.heading_bias_deg": ("number", 0.0, 360.0),
    **{f"sensors.{s}.mount.{k}": v for s in ("lidar", "radar") for k, v in _MOUNT.items()},
}
_SENSORS = ("lidar", "radar", "ais", "nav")
_SECTIONS = ("tdm", "own_ship", "sensors", *(f"sensors.{s}" for s in _SENSORS),
             "sensors.lidar.mount", "sensors.radar.mount")
#: How alike (difflib ratio) a key must be to a known key its section lacks to be taken for its misspelling: one
#: character added or dropped (keys of four characters or more) or changed (seven or more) is over it; the closest
#: key raysim writes beside the TDM's, ``sensors.radar.beam_el_deg`` to ``beam_az_deg``, is 0.82.
MISSPELT_RATIO = 0.85


def _known_keys() -> dict[str, frozenset[str]]:
    """Section -> the keys the TDM reads in it (:data:`CHECKED`, and each sensor's ``enabled`` and ``mount``)."""
    known: dict[str, set[str]] = {section: set() for section in _SECTIONS if section != "sensors"}
    for key_path in CHECKED:
        section, _, key = key_path.rpartition(".")
        known[section].add(key)
    for sensor in _SENSORS:
        known[f"sensors.{sensor}"] |= {"enabled", "mount"} if sensor in ("lidar", "radar") else {"enabled"}
    return {section: frozenset(keys) for section, keys in known.items()}


_KNOWN = _known_keys()


def _lookup(data: dict, key_path: str):
    """The value at a dotted key path, or None when any part is absent or null."""
    node = data
    for part in key_path.split("."):
        if not isinstance(node, dict):
            return None
        node = node.get(part)
    return node


def check_scenario(data: object, path: Path) -> dict:
    """``data`` (a parsed scenario) if the TDM's keys are as the module docstring says; else a RecordingError."""
    if not isinstance(data, dict):
        raise RecordingError(str(path), "(top level)", f"must be a mapping, not {values.describe(data)}")
    for section in _SECTIONS:
        value = _lookup(data, section)
        if value is not None:
            values.mapping(value, path, section)
    _check_misspelt(data, path)
    for sensor in _SENSORS:
        enabled = _lookup(data, f"sensors.{sensor}.enabled")
        if enabled is not None:
            values.boolean(enabled, path, f"sensors.{sensor}.enabled")
    for key_path, (kind, low, high) in CHECKED.items():
        value = _lookup(data, key_path)
        if value is None:
            continue
        if kind == "count":
            values.integer(value, path, key_path, int(low), int(high))
        else:
            values.number(value, path, key_path, low, high, low_open=kind == "rate")
    return data


def _check_misspelt(data: dict, path: Path) -> None:
    """A RecordingError for the first key of a section the TDM reads that looks like a misspelling of a key the
    section lacks (module docstring)."""
    for section, known in _KNOWN.items():
        node = _lookup(data, section)
        if not isinstance(node, dict):
            continue
        missing = sorted(known - set(node))
        for key in node:
            if isinstance(key, str) and key not in known:
                close = difflib.get_close_matches(key, missing, n=1, cutoff=MISSPELT_RATIO)
                if close:
                    raise RecordingError(str(path), f"{section}.{key}", f"unknown key (did you mean {close[0]!r}?)")


def read_scenario(recording: Path) -> dict:
    """The recording's resolved ``scenario.yaml``, checked (module docstring).

    Parameters
    ----------
    recording : Path
        The recording directory.

    Returns
    -------
    dict
        The parsed scenario, unchanged.

    Raises
    ------
    RecordingError
        Missing or unreadable file, not UTF-8, not YAML, not a mapping, or a value the TDM uses
        out of its type or bounds.
    """
    path = Path(recording) / SCENARIO
    text = decode_utf8(read_bytes(path, missing="missing: not a recording directory", max_bytes=MAX_SCENARIO_BYTES),
                       path)
    if not text.strip():
        raise RecordingError(str(path), "(file)", "empty: not a scenario")
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        raise RecordingError(str(path), f"line {mark.line + 1}" if mark else "(file)", "not valid YAML") from None
    except RecursionError:
        raise RecordingError(str(path), "(file)", "not valid YAML: nested too deeply") from None
    return check_scenario(data, path)


def nav_settings(scenario: dict) -> dict:
    """The own ship's navigation section of a checked scenario (``sensors.nav``: its noise and bias figures), or an
    empty mapping where it is absent or disabled (``enabled: false``)."""
    nav = (scenario.get("sensors") or {}).get("nav") or {}
    return nav if nav.get("enabled", True) else {}
