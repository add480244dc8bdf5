"""Make the README's pictures of near shore: a radar PPI with a ship hidden behind the island, and the map.

    python docs/pictures/make_land_pictures.py [SCENARIO] [--time S] [--check S ...]

Writes next to this script:

- ``<name>_ppi.png``: the renderer's own north-up PPI of the radar revolution starting at ``--time``
  (default 165 s: in scenarios/near_shore.yaml coaster_north is then behind the island).
- ``<name>_map.png``: ``map.png`` of the whole run (raysim.recording.map_picture), drawn from the
  truth of the scenario's full duration and its land, without rendering the sensors.

For the revolutions at ``--check`` times (default 60, 165 and 240 s) and at ``--time`` it prints
which objects the radar's rays hit (the sweep's ``object_id`` list), so a caption can say when a ship
is hidden.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
from pathlib import Path

from groundfloor.recording import LAND
from raysim.land.recording import write_land_geojson
from raysim.materials import material_index
from raysim.recording.map_picture import write_map
from raysim.recording.ppi import PpiLabels, ppi_image
from raysim.render import write_truth
from raysim.scenario import load_scenario, scenario_to_yaml
from raysim.sensors.carrier import CarrierScene
from raysim.sensors.radar import RadarRenderer
from raysim.world import World

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]


def write_run_map(scenario, world: World, out: Path) -> None:
    """``map.png`` of the whole run, from its truth and land written into a scratch recording."""
    with tempfile.TemporaryDirectory() as scratch:
        recording = Path(scratch)
        (recording / "scenario.yaml").write_text(scenario_to_yaml(scenario), encoding="utf-8")
        land_ids = {o.name: o.object_id for o in world.objects if o.kind == "land"}
        if scenario.land:
            write_land_geojson(scenario, land_ids, recording / LAND)
        write_truth(world, recording / "truth.jsonl", False)
        write_map(recording, scenario.start_time)
        shutil.copyfile(recording / "map.png", out)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenario", nargs="?", default=str(REPO / "scenarios" / "near_shore.yaml"))
    parser.add_argument("--time", type=float, default=165.0, help="scenario time of the PPI's revolution, s")
    parser.add_argument("--check", type=float, nargs="*", default=[60.0, 165.0, 240.0],
                        help="times of revolutions whose objects are listed, s")
    args = parser.parse_args(argv)
    scenario = load_scenario(Path(args.scenario))
    world = World(scenario)
    names = {o.object_id: o.name for o in world.objects}
    scene = CarrierScene(world.scene_objects(), carrier_id=world.own_ship.object_id, sea_material=material_index("sea"))
    renderer = RadarRenderer(world, scene)
    for time_s in sorted(set(args.check) | {args.time}):
        sweep = renderer.render_revolution(int(time_s / renderer.rev_s))
        seen = sorted(names[int(i)] for i in sweep["object_id"])
        hidden = sorted(set(names.values()) - set(seen) - {world.own_ship.name})
        print(f"revolution at t = {float(sweep['time'][0]):.1f} s: radar sees {', '.join(seen)}; "
              f"not seen: {', '.join(hidden) or 'none'}")
        if time_s == args.time:
            out = HERE / f"{scenario.name}_ppi.png"
            ppi_image(sweep["echo"], sweep["azimuth_deg"], sweep["heading_deg"], sweep["range_m"],
                      time_s=sweep["time"], labels=PpiLabels.from_scenario(scenario)).save(out)
            print(out)
    out = HERE / f"{scenario.name}_map.png"
    write_run_map(scenario, world, out)
    print(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
