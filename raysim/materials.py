"""Optical (905 nm) and radar (X band) properties of the materials meshes are made of.

Every mesh face carries a material index into :data:`MATERIALS`; sensors look the
properties up per hit with the arrays of :func:`material_table`, vectorised::

    table = material_table()
    rho = table["reflectance_905nm"][face_material[hit_face]]

Sources and conventions (see docs/reference.md sections 2 and 3):

- ``reflectance_905nm`` is the diffuse (Lambertian) reflectance at the HDL-32E's 905 nm
  wavelength, 0..1. The HDL-32E reports 0-100 % diffuse reflectivity in its reflectivity byte
  and 101-255 for retro-reflectors (firmware >= 2.0), hence the separate ``retroreflective``
  flag. Figures marked "(unverified)" are plausible defaults, not primary measurements.
- ``radar_reflectivity_db`` is the power reflectivity relative to a perfect conductor at
  X band (9.41 GHz): 0 dB for metal; for dielectrics it is computed here from the Fresnel
  normal-incidence formula ``|(1 - sqrt(er)) / (1 + sqrt(er))|^2`` with the material's
  ``relative_permittivity`` (ice, er = 3.15, gives about -11 dB, REFERENCE section 3 item 6).
- ``radar_roughness_m`` is the rms surface height that splits the radar reflection into a
  coherent (facet physical optics) and an incoherent part (Rayleigh roughness; unverified defaults).
- ``specular_exponent`` is the exponent ``n`` of the radar rough-surface lobe ``cos^n(theta)``
  (theta = angle between the facet normal and the direction back to the radar). It is derived
  here from a documented half-power half-width of the lobe: a smooth metal plate has a very
  narrow lobe (large n), rough ice and snow a broad one (small n). All lobe widths are
  engineering defaults (unverified).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Material",
    "MATERIALS",
    "fresnel_normal_reflectivity_db",
    "specular_exponent_from_half_width_deg",
    "material_index",
    "material_names",
    "material_table",
]


@dataclass(frozen=True)
class Material:
    """Optical and radar properties of one surface material.

    Attributes
    ----------
    name : str
        Material name; part of the API (scenarios and meshes refer to it).
    reflectance_905nm : float
        Diffuse Lambertian reflectance at 905 nm, 0..1.
    retroreflective : bool
        True for retro-reflective surfaces (the HDL-32E reports them as 101..255).
    radar_reflectivity_db : float
        Power reflectivity relative to a perfect conductor at 9.41 GHz, dB (0 for metal).
    relative_permittivity : float or None
        Real relative permittivity at X band for dielectrics; None for conductors.
    specular_exponent : float
        Exponent n of the radar rough-surface lobe ``cos^n(theta)``; larger is sharper.
    radar_roughness_m : float
        Rms surface height at radar wavelengths, m: the coherent (mirror-like) fraction of the
        reflection is ``exp(-(4 pi h cos(theta) / lambda)^2)`` (Rayleigh roughness), the rest goes
        into the rough-surface lobe.
    source : str
        Where the numbers come from; "(unverified)" marks engineering defaults.
    """

    name: str
    reflectance_905nm: float
    retroreflective: bool
    radar_reflectivity_db: float
    relative_permittivity: float | None
    specular_exponent: float
    radar_roughness_m: float
    source: str


def fresnel_normal_reflectivity_db(relative_permittivity: float) -> float:
    """Power reflectivity of a flat dielectric half-space at normal incidence, in dB.

    ``R = |(1 - sqrt(er)) / (1 + sqrt(er))|^2``, relative to a perfect conductor (R = 1).

    Parameters
    ----------
    relative_permittivity : float
        Real relative permittivity er > 0 (non-magnetic medium, loss ignored).

    Returns
    -------
    float
        ``10 log10(R)`` in dB (<= 0; -inf for er == 1).
    """
    if not relative_permittivity > 0.0:
        raise ValueError(f"relative permittivity must be > 0, got {relative_permittivity}")
    root_er = math.sqrt(relative_permittivity)
    reflectivity = ((1.0 - root_er) / (1.0 + root_er)) ** 2
    return 10.0 * math.log10(reflectivity) if reflectivity > 0.0 else -math.inf


def specular_exponent_from_half_width_deg(half_width_deg: float) -> float:
    """Exponent n such that ``cos^n`` falls to one half at ``half_width_deg``.

    ``n = ln(2) / -ln(cos(half_width))``; for small angles ``n ~ 1.386 / half_width_rad^2``.

    Parameters
    ----------
    half_width_deg : float
        Half-power half-width of the specular lobe, degrees, in (0, 90).

    Returns
    -------
    float
        The lobe exponent (dimensionless).
    """
    if not 0.0 < half_width_deg < 90.0:
        raise ValueError(f"half width must be in (0, 90) deg, got {half_width_deg}")
    return math.log(2.0) / -math.log(math.cos(math.radians(half_width_deg)))


# --- Relative permittivities at X band (real part) -------------------------------------------
# Ice: 3.15 (docs/reference.md section 3 item 6; fresh/glacier ice is about 3.15-3.2 from MHz to GHz).
ICE_PERMITTIVITY = 3.15
# Dry snow, density about 0.3 g/cm^3: er = 1 + 1.7 rho + 0.7 rho^2 ~ 1.57 (Tiuri et al. 1984
# dry-snow formula, quoted from memory) (unverified); rounded to 1.6.
SNOW_PERMITTIVITY = 1.6
# Sea water at 9.4 GHz: real part about 60 (Debye model of saline water near 15-20 C) (unverified).
SEA_WATER_PERMITTIVITY = 60.0
# Glass-reinforced plastic (E-glass/polyester laminate): about 4 at X band (unverified);
# gives about -9.5 dB, the "about -10 dB" usually quoted for GRP hulls (unverified).
GRP_PERMITTIVITY = 4.0
# Dry wood: about 2 (unverified).
WOOD_PERMITTIVITY = 2.0
# Dry concrete: about 6 at X band (unverified; 4.5-6 is the usual range; rebar ignored).
CONCRETE_PERMITTIVITY = 6.0
# Asphalt: about 4 (unverified; 3-6).
ASPHALT_PERMITTIVITY = 4.0
# Rubber (carbon-black loaded fender rubber): about 3 (unverified).
RUBBER_PERMITTIVITY = 3.0
# Dry coastal rock (granite, gneiss): 5.5 (unverified). Dry rocks' permittivity from 0.5 to 18 GHz was
# measured for 80 samples by Ulaby, Bengal, Dobson, East, Garvin and Evans, "Microwave dielectric
# properties of dry rocks", IEEE TGRS 28(3), 1990, where it depends mostly on bulk density; the value
# here is a typical figure for a granite of density about 2.6 g/cm^3, not read from that paper.
ROCK_PERMITTIVITY = 5.5
# Dry beach sand: 3.0 (unverified); dry soils are about 2.5-3.5 at X band (Hallikainen, Ulaby, Dobson,
# El-Rayes and Wu, "Microwave dielectric behavior of wet soil - Part I", IEEE TGRS 23(1), 1985, whose
# curves start from the dry soil's value; not read from it). Wet sand at the waterline is much higher.
SAND_PERMITTIVITY = 3.0
# Vegetation as a surface: an EFFECTIVE value of 3.0 (unverified) that, with a Lambertian lobe, stands
# for a canopy's volume scattering; the leaves themselves are far higher (20-40 for fresh leaves, El-Rayes
# and Ulaby, "Microwave dielectric spectrum of vegetation - Part I", IEEE TGRS 25(5), 1987; unverified).
VEGETATION_PERMITTIVITY = 3.0

# --- Radar specular-lobe half-power half-widths (engineering defaults, unverified) -----------
# Smooth metal plates, sea surface: 5 deg (a 0.5 m facet at lambda = 3.19 cm has a
# lambda/(2a) ~ 1.8 deg lobe; 5 deg allows for dents, rivets and paint) (unverified).
SMOOTH_HALF_WIDTH_DEG = 5.0
# Moderately rough dielectrics: GRP 15 deg, weathered ice 35 deg (unverified).
ICE_HALF_WIDTH_DEG = 35.0  # weathered berg faces: broad, so berg RCS follows projected area (REF 3.6)
GRP_HALF_WIDTH_DEG = 15.0
# Rough surfaces (wood, concrete, rubber): 30 deg; very rough/volume scatterers (snow,
# asphalt): 45 deg (unverified).
ROUGH_HALF_WIDTH_DEG = 30.0
VERY_ROUGH_HALF_WIDTH_DEG = 45.0
# Trihedral corner reflector: -3 dB full beam width about 40 deg (unverified).
CORNER_REFLECTOR_HALF_WIDTH_DEG = 20.0

# Painted steelwork of ships and structures as meshes describe it (flat panels without the fittings,
# rails, welds and small corners that make real ships bright from every aspect): a Lambertian lobe
# (cos^n falls to one half at 60 deg for n = 1) (unverified).
STRUCTURE_HALF_WIDTH_DEG = 60.0

# --- Radar rms roughness heights (engineering defaults, unverified) ---------------------------
# Rayleigh criterion at lambda = 3.19 cm: h << lambda / (8 cos) ~ 4 mm is smooth. Painted plate,
# gelcoat: 0.5 mm (mirror-like); weathered berg ice: 1 cm (fully rough at X band); snow 2 cm;
# timber, concrete, rubber: 3 mm; asphalt 5 mm; the sea is never a target (its echo is clutter): 0.
SMOOTH_ROUGHNESS_M = 0.0005
STRUCTURE_ROUGHNESS_M = 0.003  # coherent fraction exp(-(4 pi h / lambda)^2) = 0.25 at normal incidence
ICE_ROUGHNESS_M = 0.01
SNOW_ROUGHNESS_M = 0.02
ROUGH_ROUGHNESS_M = 0.003
ASPHALT_ROUGHNESS_M = 0.005
# Land: coastal rock and vegetation are fully rough at X band (rock faces: 2 cm; a canopy: 5 cm); sand is
# smoother (2 mm ripples of grains; larger ripples and dunes are left to the mesh) (unverified).
ROCK_ROUGHNESS_M = 0.02
VEGETATION_ROUGHNESS_M = 0.05
SAND_ROUGHNESS_M = 0.002


def _dielectric(
    name: str, reflectance_905nm: float, permittivity: float, half_width_deg: float, roughness_m: float, source: str
) -> Material:
    """A non-retroreflective dielectric material with Fresnel radar reflectivity."""
    return Material(
        name=name,
        reflectance_905nm=reflectance_905nm,
        retroreflective=False,
        radar_reflectivity_db=fresnel_normal_reflectivity_db(permittivity),
        relative_permittivity=permittivity,
        specular_exponent=specular_exponent_from_half_width_deg(half_width_deg),
        radar_roughness_m=roughness_m,
        source=source,
    )


def _conductor(
    name: str, reflectance_905nm: float, retroreflective: bool, half_width_deg: float, roughness_m: float, source: str
) -> Material:
    """A metallic (perfectly conducting at X band, 0 dB) material."""
    return Material(
        name=name,
        reflectance_905nm=reflectance_905nm,
        retroreflective=retroreflective,
        radar_reflectivity_db=0.0,
        relative_permittivity=None,
        specular_exponent=specular_exponent_from_half_width_deg(half_width_deg),
        radar_roughness_m=roughness_m,
        source=source,
    )


#: All materials; the position in this tuple is the material index stored in mesh arrays.
#: The order is stable: append new materials at the end, never reorder.
MATERIALS: tuple[Material, ...] = (
    _conductor(
        "steel_painted", 0.30, False, STRUCTURE_HALF_WIDTH_DEG, STRUCTURE_ROUGHNESS_M,
        "905 nm: 0.30 for grey/white marine paint (unverified); radar: metal, 0 dB; ship and harbour "
        "steelwork: the rough part (3 mm, Lambertian lobe) stands for the structure a mesh leaves out "
        "(fittings, rails, welds, small corners) (unverified).",
    ),
    _conductor(
        "aluminium", 0.60, False, SMOOTH_HALF_WIDTH_DEG, SMOOTH_ROUGHNESS_M,
        "905 nm: weathered aluminium 0.59-0.61 at 0.9 um (HELIOS++ spectral library, "
        "docs/reference.md section 2); radar: metal, 0 dB.",
    ),
    _dielectric(
        "ice", 0.40, ICE_PERMITTIVITY, ICE_HALF_WIDTH_DEG, ICE_ROUGHNESS_M,
        "905 nm: 0.40, iceberg ice is darker in the near infrared than in the visible "
        "(docs/reference.md section 2; value unverified); radar: Fresnel with er = 3.15 "
        "(docs/reference.md section 3 item 6), about -11 dB.",
    ),
    _dielectric(
        "snow", 0.80, SNOW_PERMITTIVITY, VERY_ROUGH_HALF_WIDTH_DEG, SNOW_ROUGHNESS_M,
        "905 nm: 0.80 for fresh snow at 0.9 um (unverified); radar: Fresnel with dry-snow "
        "er = 1.6 (unverified).",
    ),
    _dielectric(
        "grp", 0.50, GRP_PERMITTIVITY, GRP_HALF_WIDTH_DEG, SMOOTH_ROUGHNESS_M,
        "905 nm: 0.50 for white gelcoat (unverified); radar: Fresnel with er = 4.0, "
        "about -10 dB (unverified).",
    ),
    _dielectric(
        "wood", 0.45, WOOD_PERMITTIVITY, ROUGH_HALF_WIDTH_DEG, ROUGH_ROUGHNESS_M,
        "905 nm: 0.45 for weathered timber (unverified); radar: Fresnel with er = 2.0 "
        "(unverified).",
    ),
    _dielectric(
        "concrete", 0.40, CONCRETE_PERMITTIVITY, ROUGH_HALF_WIDTH_DEG, ROUGH_ROUGHNESS_M,
        "905 nm: 0.40 (unverified); radar: Fresnel with er = 6.0 (unverified).",
    ),
    _dielectric(
        "asphalt", 0.28, ASPHALT_PERMITTIVITY, VERY_ROUGH_HALF_WIDTH_DEG, ASPHALT_ROUGHNESS_M,
        "905 nm: asphalt 0.28 at 0.9 um (HELIOS++ spectral library, docs/reference.md section 2); "
        "radar: Fresnel with er = 4.0 (unverified).",
    ),
    _dielectric(
        "rubber", 0.05, RUBBER_PERMITTIVITY, ROUGH_HALF_WIDTH_DEG, ROUGH_ROUGHNESS_M,
        "905 nm: 0.05 for black fender rubber (unverified); radar: Fresnel with er = 3.0 "
        "(unverified).",
    ),
    _conductor(
        "retroreflector", 1.0, True, CORNER_REFLECTOR_HALF_WIDTH_DEG, SMOOTH_ROUGHNESS_M,
        "905 nm: retro-reflective (HDL-32E reports 101-255, docs/reference.md section 2), "
        "diffuse part 1.0 (unverified); radar: 0 dB, corner-reflector-like lobe (unverified).",
    ),
    _dielectric(
        "sea", 0.02, SEA_WATER_PERMITTIVITY, SMOOTH_HALF_WIDTH_DEG, 0.0,
        "905 nm: 0.02, Fresnel reflectance of water, specular (docs/reference.md section 2); "
        "radar: Fresnel with sea-water er = 60 at X band (unverified).",
    ),
    # Land (issue 20); "concrete" above serves quays and piers.
    _dielectric(
        "rock", 0.30, ROCK_PERMITTIVITY, VERY_ROUGH_HALF_WIDTH_DEG, ROCK_ROUGHNESS_M,
        "905 nm: 0.30 for weathered granite/gneiss (unverified; granite spectra of the ASTER spectral "
        "library, Baldridge et al. 2009, are the place to check); radar: Fresnel with dry-rock er = 5.5 "
        "(unverified; dry rocks measured by Ulaby et al., IEEE TGRS 28(3), 1990), 2 cm rough.",
    ),
    _dielectric(
        "vegetation", 0.45, VEGETATION_PERMITTIVITY, STRUCTURE_HALF_WIDTH_DEG, VEGETATION_ROUGHNESS_M,
        "905 nm: 0.45, green leaves' near-infrared plateau beyond the red edge (unverified; a canopy with "
        "gaps and shadow is darker); radar: an effective er = 3.0 with a Lambertian lobe for the canopy's "
        "volume scattering (unverified).",
    ),
    _dielectric(
        "sand", 0.45, SAND_PERMITTIVITY, ROUGH_HALF_WIDTH_DEG, SAND_ROUGHNESS_M,
        "905 nm: 0.45 for dry light quartz sand (unverified; USGS spectral library sand spectra are the "
        "place to check); radar: Fresnel with dry-sand er = 3.0 (unverified; dry soils, Hallikainen et al., "
        "IEEE TGRS 23(1), 1985).",
    ),
)

_INDEX_BY_NAME: dict[str, int] = {m.name: i for i, m in enumerate(MATERIALS)}


def material_names() -> tuple[str, ...]:
    """Names of all materials in index order."""
    return tuple(m.name for m in MATERIALS)


def material_index(name: str) -> int:
    """Index of a material in :data:`MATERIALS`.

    Parameters
    ----------
    name : str
        Material name, e.g. ``"ice"``.

    Returns
    -------
    int
        Position in :data:`MATERIALS`.

    Raises
    ------
    KeyError
        If the name is unknown; the message lists the valid names.
    """
    try:
        return _INDEX_BY_NAME[name]
    except (KeyError, TypeError):
        valid = ", ".join(material_names())
        raise KeyError(f"unknown material {name!r}; valid materials: {valid}") from None


def material_table() -> dict[str, np.ndarray]:
    """Per-index property arrays for vectorised lookup by material-index arrays.

    Returns
    -------
    dict of str to numpy.ndarray
        Fresh arrays of shape (M,), M = ``len(MATERIALS)``, aligned with :data:`MATERIALS`:
        ``reflectance_905nm`` float32 (0..1), ``retroreflective`` bool,
        ``radar_reflectivity_db`` float32 (dB re. metal), ``specular_exponent`` float32, ``radar_roughness_m`` float32.
    """
    return {
        "reflectance_905nm": np.array([m.reflectance_905nm for m in MATERIALS], dtype=np.float32),
        "retroreflective": np.array([m.retroreflective for m in MATERIALS], dtype=bool),
        "radar_reflectivity_db": np.array(
            [m.radar_reflectivity_db for m in MATERIALS], dtype=np.float32
        ),
        "specular_exponent": np.array([m.specular_exponent for m in MATERIALS], dtype=np.float32),
        "radar_roughness_m": np.array([m.radar_roughness_m for m in MATERIALS], dtype=np.float32),
    }


def describe_markdown() -> str:
    """Markdown table of the material table with sources (docs/physics.md embeds it)."""
    lines = [
        "| index | material | reflectance 905 nm | retro | permittivity | radar dB | lobe n | roughness mm | source |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for i, m in enumerate(MATERIALS):
        er = "-" if m.relative_permittivity is None else f"{m.relative_permittivity:g}"
        lines.append(
            f"| {i} | `{m.name}` | {m.reflectance_905nm:.2f} | {'yes' if m.retroreflective else 'no'} | {er} | "
            f"{m.radar_reflectivity_db:.2f} | {m.specular_exponent:.1f} | {1000 * m.radar_roughness_m:g} | {m.source} |"
        )
    return "\n".join(lines) + "\n"
