"""Make the README's radar PPI pictures: one revolution of a scenario in calm sea, sea state 5 and rain.

    python docs/pictures/make_radar_pictures.py [SCENARIO] [--time S]

Writes ``<name>_ppi_calm.png`` (sea state 1, no rain), ``<name>_ppi_ss5.png`` (sea state 5,
16 m/s wind) and ``<name>_ppi_rain.png`` (sea state 3 with 16 mm/h rain, an IMO test case,
docs/reference.md section 3) next to this script. Each is the renderer's own north-up PPI of the
revolution starting at ``--time``, sea control (STC) at its default, rain control off.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from raysim.materials import material_index
from raysim.recording.ppi import PpiLabels, ppi_image
from raysim.scenario import load_scenario
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.world import World

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

CASES = {
    "calm": dict(sea_state=1, wind_speed_mps=3.0, rain_mm_per_h=0.0),
    "ss5": dict(sea_state=5, wind_speed_mps=16.0, rain_mm_per_h=0.0),
    "rain": dict(sea_state=3, wind_speed_mps=8.0, rain_mm_per_h=16.0),
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scenario", nargs="?", default=str(REPO / "scenarios" / "busy_open_sea.yaml"))
    parser.add_argument("--time", type=float, default=100.0, help="scenario time of the revolution, s")
    args = parser.parse_args(argv)
    base = load_scenario(Path(args.scenario))
    for case, env in CASES.items():
        scenario = dataclasses.replace(base, environment=dataclasses.replace(base.environment, **env))
        world = World(scenario)
        scene = CarrierScene(world.scene_objects(), carrier_id=world.own_ship.object_id, sea_material=material_index("sea"))
        renderer = RadarRenderer(world, scene)
        sweep = renderer.render_revolution(int(args.time / renderer.rev_s))
        out = HERE / f"{base.name}_ppi_{case}.png"
        ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"], time_s=sweep["time"],
                  labels=PpiLabels.from_scenario(scenario)).save(out)
        print(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
