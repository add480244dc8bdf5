"""Make the README's radar PPI pictures: one revolution of a scenario in four conditions.

    python docs/pictures/make_radar_pictures.py [SCENARIO] [--time S]

Writes next to this script, each the renderer's own north-up PPI of the revolution starting at
``--time`` (default 100 s), sea control (STC) at its default, rain control (FTC) off,
interference rejection off:

- ``<name>_ppi_calm.png``: sea state 1, wind 3 m/s from 090, no rain.
- ``<name>_ppi_ss5.png``: sea state 5, wind 16 m/s from 090 (east): the upwind side of the
  clutter is the east.
- ``<name>_ppi_rain.png``: sea state 3, wind 8 m/s from 090, no background rain and three
  EXCELL rain cells (``environment.rain_cells``, docs/scenario.md) drifting west with the wind:
  at the picture's time 1,000 m north-east of the own ship (radius 400 m, 30 mm/h peak), 1,300 m
  south-west (600 m, 15 mm/h) and 700 m west (250 m, 50 mm/h).
- ``<name>_ppi_interference.png``: sea state 1 as the calm picture, plus another X-band radar
  (``sensors.radar.interference``) 1,500 m north-north-west of the own ship at the picture's
  time: PRF 999.6 Hz (near our 1 kHz sweep rate, so its dots walk 60 m a pulse and line up
  into arcs), 24 rpm, 0.08 us pulses, received 100 dB over our noise main beam to main beam (a
  rough one-way link budget of a 4 kW set at that distance; its sidelobes into ours still give
  about 30 dB).

Cells and the other radar are placed relative to the own ship at ``--time`` (a cell's t = 0
centre is its place at ``--time`` moved back up the wind by its drift). For each picture the
script also prints the statistics of ``make_halo_picture.echo_statistics``, the numbers that
docs/radar_vs_real.md sets beside a real HALO's.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path

import numpy as np

from make_halo_picture import echo_statistics, format_statistics
from groundfloor.frames import LocalFrame
from raysim.materials import material_index
from raysim.recording.ppi import PpiLabels, ppi_image
from raysim.scenario import load_scenario
from raysim.scenario_format import Interferer, RainCell
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.world import World

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

WIND_FROM_DEG = 90.0
#: rain cells at the picture's time: (east m, north m) from the own ship, EXCELL radius m, peak mm/h
RAIN_CELLS = ((700.0, 700.0, 400.0, 30.0), (-920.0, -920.0, 600.0, 15.0), (-700.0, 0.0, 250.0, 50.0))
#: the other radar at the picture's time: (east m, north m) from the own ship, PRF Hz, rpm, pulse us,
#: received level over our noise main beam to main beam, dB (a rough one-way budget: 4 kW, 30 dBi
#: its side, 25 dBi ours, 1.5 km, 3.2 cm, 25 MHz noise bandwidth, 5 dB noise figure: about 100 dB)
INTERFERER = (-574.0, 1386.0, 999.6, 24.0, 0.08, 100.0)

CASES = {
    "calm": dict(environment=dict(sea_state=1, wind_speed_mps=3.0, wind_from_deg=WIND_FROM_DEG, rain_mm_per_h=0.0)),
    "ss5": dict(environment=dict(sea_state=5, wind_speed_mps=16.0, wind_from_deg=WIND_FROM_DEG, rain_mm_per_h=0.0)),
    "rain": dict(environment=dict(sea_state=3, wind_speed_mps=8.0, wind_from_deg=WIND_FROM_DEG, rain_mm_per_h=0.0),
                 rain_cells=RAIN_CELLS),
    "interference": dict(environment=dict(sea_state=1, wind_speed_mps=3.0, wind_from_deg=WIND_FROM_DEG,
                                          rain_mm_per_h=0.0), interference=INTERFERER),
}


def own_ship_xy_m(scenario, time_s: float) -> tuple[np.ndarray, LocalFrame]:
    """Own ship's (east, north) position at ``time_s``, m, and the scenario's local frame."""
    world = World(scenario)
    return world.own_ship.motion.poses(np.array([time_s])).position_m[0, :2], world.frame


def case_scenario(base, case: dict, time_s: float):
    """``base`` with a case's environment, rain cells and interferer (placed about the own ship at ``time_s``)."""
    env = case["environment"]
    own_xy, frame = own_ship_xy_m(base, time_s)
    cells = []
    towards = math.radians(env["wind_from_deg"] + 180.0)
    drift_m = env["wind_speed_mps"] * time_s * np.array([math.sin(towards), math.cos(towards)])
    for east_m, north_m, radius_m, rate in case.get("rain_cells", ()):
        lat, lon = frame.to_geodetic(*(own_xy + (east_m, north_m) - drift_m))
        cells.append(RainCell(position=(float(lat), float(lon)), radius_m=radius_m, rate_mm_per_h=rate))
    environment = dataclasses.replace(base.environment, **env, rain_cells=tuple(cells))
    radar = dataclasses.replace(base.sensors.radar, interference=(), interference_rejection="off")
    if "interference" in case:
        east_m, north_m, prf_hz, rpm, pulse_us, level_db = case["interference"]
        lat, lon = frame.to_geodetic(*(own_xy + (east_m, north_m)))
        radar = dataclasses.replace(radar, interference=(Interferer(
            position=(float(lat), float(lon)), prf_hz=prf_hz, rpm=rpm, pulse_length_us=pulse_us, level_db=level_db),))
    sensors = dataclasses.replace(base.sensors, radar=radar)
    return dataclasses.replace(base, environment=environment, sensors=sensors)


def upwind_downwind(sweep: dict[str, np.ndarray], wind_from_deg: float, near_m: float = 200.0,
                    far_m: float = 900.0, half_width_deg: float = 45.0) -> tuple[float, float]:
    """Fraction of non-zero cells at ``near_m``..``far_m`` within +-``half_width_deg`` of the upwind
    and of the downwind true bearing: (upwind, downwind)."""
    true_deg = (sweep["heading_deg"] + sweep["azimuth_deg"]) % 360.0
    ring = (sweep["range_m"] >= near_m) & (sweep["range_m"] <= far_m)
    fractions = []
    for towards in (wind_from_deg, wind_from_deg + 180.0):
        sector = np.abs((true_deg - towards + 180.0) % 360.0 - 180.0) <= half_width_deg
        fractions.append(float((sweep["echo"][np.ix_(sector, ring)] > 0).mean()))
    return fractions[0], fractions[1]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenario", nargs="?", default=str(REPO / "scenarios" / "busy_open_sea.yaml"))
    parser.add_argument("--time", type=float, default=100.0, help="scenario time of the revolution, s")
    parser.add_argument("--cases", nargs="*", default=list(CASES), choices=list(CASES), help="pictures to make")
    args = parser.parse_args(argv)
    base = load_scenario(Path(args.scenario))
    for name in args.cases:
        scenario = case_scenario(base, CASES[name], args.time)
        world = World(scenario)
        scene = CarrierScene(world.scene_objects(), carrier_id=world.own_ship.object_id, sea_material=material_index("sea"))
        renderer = RadarRenderer(world, scene)
        sweep = renderer.render_revolution(int(args.time / renderer.rev_s))
        out = HERE / f"{base.name}_ppi_{name}.png"
        ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"], time_s=sweep["time"],
                  labels=PpiLabels.from_scenario(scenario)).save(out)
        print(out)
        order = np.argsort(sweep["azimuth_deg"], kind="stable")
        scale_m = float(sweep["range_m"][-1])
        print(format_statistics(name, echo_statistics(sweep["echo"][order], scale_m), scale_m, sweep["echo"].shape))
        up, down = upwind_downwind(sweep, scenario.environment.wind_from_deg)
        print(f"  non-zero at 200-900 m within 45 deg of upwind {100 * up:.2f} %, of downwind {100 * down:.2f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
