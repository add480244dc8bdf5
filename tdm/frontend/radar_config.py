"""The radar front end's settings (:class:`RadarFrontEndConfig`) and the radar's mount.

Part of the radar front end (:mod:`tdm.frontend.radar`, module docstring for the method).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import brentq

from groundfloor.recording import RadarDescription
from tdm.frames import Mount

__all__ = ["OS_RANK_FRACTION", "RadarFrontEndConfig", "ca_alpha", "mount_from_scenario", "os_alpha"]

#: Default rank of OS-CFAR as a fraction of the training cells: k about 3N/4 (Rohling 1983;
#: docs/reference.md section 5).
OS_RANK_FRACTION = 0.75
#: Bracket of the OS-CFAR multiplier and the solver's tolerances (alpha lies between these for any
#: N, k and Pfa the configuration allows).
_OS_ALPHA_BRACKET = (1e-9, 1e12)
_OS_ALPHA_TOLERANCE = 1e-12


@dataclass(frozen=True)
class RadarFrontEndConfig:
    """Parameters of the radar front end, with their defaults and sources.

    Attributes
    ----------
    cfar : str
        ``"os"`` (ordered statistic, default: robust at clutter edges and next to other targets,
        docs/reference.md section 5) or ``"ca"`` (cell averaging).
    pfa : float
        Design false-alarm probability per cell on exponential noise. Default 1e-4, the IMO
        detection basis (docs/reference.md section 3 table).
    training_cells : int
        N, training cells per CUT in all (N/2 each side in the interior). Default 32 (29 m each side
        at 1.81 m samples: longer than a sea-clutter patch, docs/reference.md 3.8).
    guard_cells : int
        G, guard cells each side of the CUT, not trained on. Default 4 (7 m: the 2.5 m range
        point-spread of docs/reference.md 3.3 with margin).
    os_rank : int or None
        k of OS-CFAR (1-based). None: ``round(3 N / 4)`` (docs/reference.md section 5).
    min_echo_level : int
        Lowest video level a detection may have. Default 1 (anything over the receiver's floor).
    fill_level : int
        Lowest level of the cells that fill a gap between two detections on a spoke (step 3);
        0 turns filling off. Default 1.
    clutter_map_detection : bool
        Also detect every cell whose beam-integrated power reaches its block's clutter-map seed threshold
        (step 3b, :mod:`tdm.frontend.radar_extended`): the interior of an echo longer than the range CFAR's
        window, which masks itself, so that an extended object is one plot. Default True since 2026-11-29 (stop 47),
        with the radar tracker's weak limit rising with a plot's size
        (:attr:`tdm.tracker_config.TrackerConfig.weak_rise_db_per_doubling`), which keeps the wide sea-clutter plots
        it makes from confirming (benchmarks/results/tdm_clutter_map_detection.md).
    video_threshold_db : float
        Power where video level 1 starts, dB over the mean thermal noise. Default 9.6 dB, the level
        noise alone crosses with probability 1e-4 (``10 log10(-ln 1e-4)``; the IMO Pfa,
        docs/reference.md section 3 table); a receiver sets its floor so (docs/reference.md 3.10). Unverified for a
        real set, whose gain control moves it.
    video_step_db : float
        dB per video level (log video, docs/reference.md 3.10). Default 3 dB (16 levels over 45 dB;
        unverified for a real set).
    integration_spokes : int
        Spokes averaged for the seed test (step 5). Default 16 (2.8 deg, about half the 5.2 deg
        beam, within which a target's two-way echo stays within 2 dB of its peak).
    clutter_block_spokes, clutter_block_samples : int
        Clutter-map block, cells. Defaults 16 x 8 (2.8 deg x 14.5 m: a sea-clutter patch).
    clutter_window_blocks, clutter_guard_blocks : (int, int)
        Clutter-map annulus, blocks (azimuth, range): the window minus its central guard. Defaults
        (65, 5) minus (5, 3): 183 deg x 72 m minus 14 deg x 43 m. Wide in azimuth, so that targets
        fill few of its 310 blocks; narrow in range, to follow the clutter's fall with range and
        the sensitivity-time control's rise near the antenna (docs/reference.md 3.10). On rendered
        sea states 2 and 4 it found more targets at fewer false plots than (33, 9).
    clutter_quantile : float
        Quantile of the annulus's block maxima taken as the local clutter level. Default 0.9
        (robust while targets fill under 10 % of the annulus).
    clutter_margin_db : float
        How far a plot's peak integrated power must exceed the clutter level, dB. Default 10 dB
        (measured on rendered recordings: about 7 false plots per sweep at sea state 4 and under 1
        at sea state 2, with 95 % and 100 % of the objects found; 8.5 dB: 20 and 2 false plots,
        12 dB: 3 and 0.1, with 91 % found at sea state 4).
    min_seed_db : float
        Lowest integrated power of a seed, dB over the mean noise. Default 10 dB (as the margin,
        over a noise-only background).
    min_plot_cells, max_plot_cells : int
        A plot has between these many cells. Defaults 6 (a few samples over a few spokes) and
        100 000 (5 % of a sweep: larger is land or a clutter field, not a target).
    min_plot_spokes : int
        Fewest spokes a plot spans. Default 3 (0.5 deg: the 5.2 deg beam smears even a weak point
        target over several spokes).
    own_ship_length_m, own_ship_beam_m : float
        Own-ship hull, metres (scenario ``own_ship``; defaults: the thesis's Odin, 10.9 x 3.5 m).
    own_ship_margin_m : float
        Margin about the hull inside which plots are the own ship, metres. Default 5 m (two range
        resolutions).
    beam_az_deg : float
        -3 dB one-way horizontal beamwidth, deg. Default 5.2 (docs/reference.md section 3 table).
    range_resolution_m : float
        Physical range resolution (FMCW bandwidth or pulse length, ``c / (2 B)``), metres.
        Default 2.5 (docs/reference.md 3.3: about 2-3 m).
    blanking_m : float
        Main-bang blanking: nearer samples hold no data and are not training cells, metres.
        Default 3 (scenario ``sensors.radar.blanking_m``).
    bearing_sigma_beam_fraction : float
        Standard deviation of a plot's bearing as a fraction of the beamwidth. Default 0.15 (the
        power-weighted centroid of a beam-smeared echo is far better than the beam: measured 0.6-1
        deg, 0.12-0.19 theta3, across the beam on rendered recordings, including the targets' own
        extent).
    extent_sigma_fraction : float
        Standard deviation of the centroid about the target's centre per metre of the target's
        visible extent. Default 0.25. The radar sees the near face, not the centre (the plots of
        rendered icebergs lie 6-9 m short of their centres), so the centre lies up to half the
        target's depth behind its plot; but that offset is a bias that stays from sweep to sweep,
        and the trackers treat the covariance as white noise: with 0.5 (median NEES about the
        truth centres 0.5-1.5) the plots' real scatter (about 2 m on the Table 3.2 vessel) was
        reported as 10 m and the radar tracks lagged every turn; 0.25 halves their heading error
        (benchmarks/results/thesis_table32.md).
    core_db : float
        How far under a plot's strongest cell its core reaches, dB (``Detections.core_width_m``: the
        cross-range width of those cells less the two-way beam's width as many dB down). Default 9: three
        video levels of 3 dB, so that a saturated echo's core still spans several levels. Looked at on
        busy_open_sea seed 31 (its bergs 20-25 m): 3 dB gave a median 0-11 m (one or two levels, ruled by the
        spoke quantisation), 6, 9 and 12 dB 12-34, 15-27 and 15-28 m.
    land_beam_fraction : float
        With a chart (the recording's land), plots within ``range sin(land_beam_fraction beam_az_deg)``
        of the land are dropped as the land's own echo smeared by the beam (:func:`tdm.land.beam_margin_m`).
        Default 1.0: a whole -3 dB beamwidth off a coast face, where the two-way pattern is 24 dB under its
        peak: a coast's echo 30-40 dB over the sea still paints there, and an echo nearer is not resolved from
        the coast's (a radar's azimuth resolution is its beamwidth), as ``land_clear_beam_fraction`` already
        held for the clutter level. 0.5 (half a beam, two-way 6 dB) until 2026-11-28: the smear's tail, 4-5
        deg past a quay's edge at 640 m, made plots 37-40 m off the chart's land (half a beam: 29 m) that
        confirmed as false targets (busy_port seeds 31 and 34, held out; docs/tdm.md). 0 turns it off. Not
        fitted to any scenario: the figure is the beam's.
    clutter_map_without_land : bool
        With a chart, a plot clear of the land (``land_clear_beam_fraction``) is measured against the
        clutter of its annulus without the blocks on the land (grown by the ``land_beam_fraction``
        smear; :mod:`tdm.frontend.radar_land`): a high quantile of an annulus 183 deg wide takes in the
        land's echo at the plot's range, which buried a clean echo in busy_port's harbour. Default
        True; no effect without land. Not fitted: the land is the chart's.
    land_clear_beam_fraction : float
        A plot whose peak lies within ``range sin(land_clear_beam_fraction beam_az_deg)`` (plus half a
        clutter block) of the land keeps the land in its clutter level: it must stand out of the land's
        own echo, smeared by the beam. Default 1.0, a whole -3 dB beamwidth off the land, where the
        two-way pattern is 24 dB under its peak (a coast's echo 40 dB over the noise still shows there).
        Not fitted to a scenario.
    sidelobe_margin_db : float or None
        A plot at least this much weaker (strength over the local clutter) than another of the scan at
        the same range, in its sidelobes, is that plot's sidelobe echo and is dropped
        (:mod:`tdm.frontend.radar_sidelobes`); None turns the rule off. Default 10 dB: the antenna's
        two-way sidelobes are 40 dB and more under its main lobe beyond 6 deg (docs/radar.md,
        "Antenna"), which the 45 dB of log video and the strongest echoes' saturation compress; 10 dB
        keeps a target that is merely somewhat weaker. Not fitted to a scenario.
    sidelobe_range_gate_m : float
        Plots this close in range count as at the same range. Default 10 m (four range resolutions:
        two plots' centroids over one extended echo).
    sidelobe_offset_deg : (float, float)
        Bearing offsets of the sidelobe region, deg. Default (5.2, 60): from one beamwidth (inside it,
        the two plots are one echo's) to where the two-way pattern (-70 dB) puts even a saturating
        echo under the video floor (docs/radar.md, "Antenna").
    echo_gap_m : float or None
        Plots that share a spoke and lie within this of each other along it are fragments of one echo
        (:mod:`tdm.frontend.radar_echoes`; ``Detections.echo_spread_m``). Default 10 m (four range resolutions, as
        ``sidelobe_range_gate_m``): further apart, the radar resolves them. None: no plot is a fragment.
    range_scale_m, spokes, samples : float, int, int or None
        The sweep geometry the configuration is for (scenario ``sensors.radar``); when set,
        :func:`radar_detections` checks each sweep against it.
    """

    cfar: str = "os"
    pfa: float = 1e-4
    training_cells: int = 32
    guard_cells: int = 4
    os_rank: int | None = None
    min_echo_level: int = 1
    fill_level: int = 1
    clutter_map_detection: bool = True
    video_threshold_db: float = 9.6
    video_step_db: float = 3.0
    integration_spokes: int = 16
    clutter_block_spokes: int = 16
    clutter_block_samples: int = 8
    clutter_window_blocks: tuple[int, int] = (65, 5)
    clutter_guard_blocks: tuple[int, int] = (5, 3)
    clutter_quantile: float = 0.9
    clutter_margin_db: float = 10.0
    min_seed_db: float = 10.0
    min_plot_cells: int = 6
    max_plot_cells: int = 100_000
    min_plot_spokes: int = 3
    own_ship_length_m: float = 10.9
    own_ship_beam_m: float = 3.5
    own_ship_margin_m: float = 5.0
    beam_az_deg: float = 5.2
    range_resolution_m: float = 2.5
    blanking_m: float = 3.0
    bearing_sigma_beam_fraction: float = 0.15
    extent_sigma_fraction: float = 0.25
    core_db: float = 9.0
    land_beam_fraction: float = 1.0
    clutter_map_without_land: bool = True
    land_clear_beam_fraction: float = 1.0
    sidelobe_margin_db: float | None = 10.0
    sidelobe_range_gate_m: float = 10.0
    sidelobe_offset_deg: tuple[float, float] = (5.2, 60.0)
    echo_gap_m: float | None = 10.0
    range_scale_m: float | None = None
    spokes: int | None = None
    samples: int | None = None

    def __post_init__(self):
        if self.cfar not in ("os", "ca"):
            raise ValueError(f"cfar must be 'os' or 'ca', not {self.cfar!r}")
        if not 0.0 < self.pfa < 1.0:
            raise ValueError(f"pfa must be in (0, 1), not {self.pfa}")
        if self.training_cells < 2 or self.training_cells % 2:
            raise ValueError(f"training_cells must be even and >= 2, not {self.training_cells}")
        if self.guard_cells < 0:
            raise ValueError(f"guard_cells must be >= 0, not {self.guard_cells}")
        if not 1 <= self.rank <= self.training_cells:
            raise ValueError(f"os_rank must be in 1..training_cells, not {self.os_rank}")
        if not 0.0 < self.clutter_quantile <= 1.0:
            raise ValueError(f"clutter_quantile must be in (0, 1], not {self.clutter_quantile}")
        if not self.core_db > 0.0:
            raise ValueError(f"core_db must be > 0, not {self.core_db}")
        for name in ("clutter_window_blocks", "clutter_guard_blocks"):
            a, r = getattr(self, name)
            if a < 1 or r < 1 or a % 2 == 0 or r % 2 == 0:
                raise ValueError(f"{name} must be two odd sizes >= 1, not {(a, r)}")

    @property
    def rank(self) -> int:
        """k of OS-CFAR (1-based)."""
        return int(self.os_rank) if self.os_rank is not None else int(round(OS_RANK_FRACTION * self.training_cells))

    @property
    def alpha(self) -> float:
        """Threshold multiplier of the configured CFAR at the configured Pfa (exponential noise)."""
        if self.cfar == "ca":
            return ca_alpha(self.training_cells, self.pfa)
        return os_alpha(self.training_cells, self.rank, self.pfa)

    @classmethod
    def from_scenario(cls, scenario: dict, **overrides) -> "RadarFrontEndConfig":
        """The configuration for a recording, from its resolved ``scenario.yaml`` (a dict).

        Reads ``sensors.radar`` (``range_m``, ``spokes``, ``samples``, ``beam_az_deg``,
        ``blanking_m``) and ``own_ship`` (``length_m``, ``beam_m``); absent keys keep the defaults.
        ``overrides`` set any field. The mount is read by :func:`mount_from_scenario`.
        """
        radar = RadarDescription.from_scenario(scenario)
        own = scenario.get("own_ship") or {}
        values: dict = {}
        for key, field_name in (("range_m", "range_scale_m"), ("spokes", "spokes"), ("samples", "samples"),
                                ("beam_az_deg", "beam_az_deg")):
            if getattr(radar, key) is not None:
                values[field_name] = getattr(radar, key)
        blanking_m = ((scenario.get("sensors") or {}).get("radar") or {}).get("blanking_m")
        if blanking_m is not None:  # not part of the recording's description: the radar front end's own
            values["blanking_m"] = float(blanking_m)
        if own.get("length_m") is not None:
            values["own_ship_length_m"] = float(own["length_m"])
        if own.get("beam_m") is not None:
            values["own_ship_beam_m"] = float(own["beam_m"])
        values.update(overrides)
        return cls(**values)


def mount_from_scenario(scenario: dict) -> Mount:
    """The radar's :class:`~tdm.frames.Mount` from a resolved scenario dict (``sensors.radar.mount``;
    :class:`groundfloor.recording.RadarDescription`)."""
    return RadarDescription.from_scenario(scenario).mount


def ca_alpha(n_training: int, pfa: float) -> float:
    """CA-CFAR multiplier ``alpha = N (Pfa^(-1/N) - 1)`` (exponential noise; docs/reference.md section 5)."""
    return float(n_training * (pfa ** (-1.0 / n_training) - 1.0))


@lru_cache(maxsize=64)
def os_alpha(n_training: int, rank: int, pfa: float) -> float:
    """OS-CFAR multiplier for the k-th smallest of N training cells (Rohling 1983, exponential noise).

    Solves ``Pfa = prod_{i=0}^{k-1} (N - i) / (N - i + alpha)`` for alpha.
    """
    n_i = n_training - np.arange(rank, dtype=float)

    def log_pfa_error(alpha: float) -> float:
        return float(np.sum(np.log(n_i / (n_i + alpha)))) - math.log(pfa)

    return float(brentq(log_pfa_error, *_OS_ALPHA_BRACKET, xtol=_OS_ALPHA_TOLERANCE,
                        rtol=_OS_ALPHA_TOLERANCE))
