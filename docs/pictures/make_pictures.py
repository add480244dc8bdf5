"""Make the README's pictures of a scenario by ray casting it with raysim's own engine.

    python docs/pictures/make_pictures.py [SCENARIO] [--time S]

Writes ``<name>_top.png`` (orthographic view from above, with the tracks of the whole run) and
``<name>_mast.png`` (a pinhole camera at the LiDAR mount, looking at the nearest ship) next to
this script. Shading is a simple Lambert model with a colour per material: these are pictures
of the geometry the sensors see, not sensor output.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from raysim.materials import MATERIALS, material_index
from raysim.scenario import load_scenario
from raysim.scene import NO_HIT, SEA_ID, Scene
from raysim.world import World

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]

COLOURS = {
    "steel_painted": (190, 70, 60), "aluminium": (200, 200, 205), "ice": (225, 240, 250), "snow": (250, 250, 250),
    "grp": (235, 235, 225), "wood": (140, 100, 60), "concrete": (170, 170, 165), "asphalt": (70, 70, 70),
    "rubber": (30, 30, 30), "retroreflector": (255, 200, 0), "sea": (25, 60, 95),
}
PALETTE = np.array([COLOURS.get(m.name, (200, 0, 200)) for m in MATERIALS], dtype=float)
SKY = np.array([170.0, 200.0, 230.0])
LIGHT = np.array([0.4, -0.3, 0.87]) / np.linalg.norm([0.4, -0.3, 0.87])


def shade(hits, directions: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours from hits: Lambert on material colour, sky for misses, haze by range."""
    colour = np.tile(SKY, (hits.range_m.shape[0], 1))
    hit = hits.object_id != NO_HIT
    base = PALETTE[np.clip(hits.material[hit], 0, len(PALETTE) - 1)]
    lambert = 0.55 + 0.45 * np.abs(hits.normal[hit].astype(float) @ LIGHT)
    sea = hits.object_id[hit] == SEA_ID
    lambert[sea] = 1.0
    colour[hit] = base * lambert[:, None]
    haze = 1.0 - np.exp(-np.where(hit, hits.range_m, 0.0) / 2500.0)
    colour = colour * (1 - haze[:, None]) + SKY * haze[:, None]
    return np.clip(colour, 0, 255).astype(np.uint8)


def top_view(world: World, scene: Scene, t_s: float, metres_per_pixel: float = 0.75) -> Image.Image:
    """Orthographic view from 300 m up over the whole run's extent, tracks drawn over it."""
    t_run = np.arange(0.0, world.scenario.duration_s, 1.0)
    tracks = [o.motion.poses(t_run).position_m[:, :2] for o in world.objects]
    lo, hi = tracks[0].min(axis=0) - 250.0, tracks[0].max(axis=0) + 250.0  # around the own ship's track
    width, height = (np.ceil((hi - lo) / metres_per_pixel)).astype(int)
    xs = lo[0] + (np.arange(width) + 0.5) * metres_per_pixel
    ys = hi[1] - (np.arange(height) + 0.5) * metres_per_pixel
    gx, gy = np.meshgrid(xs, ys)
    origins = np.stack([gx.ravel(), gy.ravel(), np.full(gx.size, 300.0)], axis=1)
    directions = np.tile([0.0, 0.0, -1.0], (gx.size, 1))
    hits = scene.cast(origins, directions, np.full(gx.size, t_s))
    image = Image.fromarray(shade(hits, directions).reshape(height, width, 3))
    draw = ImageDraw.Draw(image)
    to_px = lambda xy: [((x - lo[0]) / metres_per_pixel, (hi[1] - y) / metres_per_pixel) for x, y in xy]  # noqa: E731
    for o, track in zip(world.objects, tracks):
        if np.ptp(track, axis=0).max() > 1.0:
            draw.line(to_px(track), fill=(255, 170, 0) if o.kind == "ownship" else (120, 255, 120), width=1)
        x, y = to_px(o.motion.poses(np.array([t_s])).position_m[:, :2])[0]
        draw.text((x + 12, y - 6), o.name, fill=(255, 255, 255))
    return image


def mast_view(world: World, scene: Scene, t_s: float, size=(1280, 480), fov_deg: float = 100.0) -> Image.Image:
    """Pinhole camera at the LiDAR mount at time t, looking at the nearest ship."""
    own = world.own_ship.motion.poses(np.array([t_s]))
    mount = world.scenario.sensors.lidar.mount
    eye = own.to_world(np.array([[mount.x_m, mount.y_m, mount.z_m]]))[0]
    ships = [o for o in world.objects if o.kind == "ship"] or list(world.objects[1:])
    centres = np.array([o.motion.poses(np.array([t_s])).position_m[0] for o in ships])
    target = centres[np.argmin(np.hypot(*(centres[:, :2] - eye[:2]).T))] + [0.0, 0.0, 4.0]
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    w, h = size
    f = (w / 2) / np.tan(np.radians(fov_deg) / 2)
    u, v = np.meshgrid(np.arange(w) - w / 2 + 0.5, h / 2 - np.arange(h) - 0.5)
    directions = forward * f + right * u.ravel()[:, None] + up * v.ravel()[:, None]
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    origins = np.tile(eye, (directions.shape[0], 1))
    hits = scene.cast(origins, directions, np.full(directions.shape[0], t_s))
    return Image.fromarray(shade(hits, directions).reshape(h, w, 3))


def lidar_sweep_view(world: World, t_s: float, size_px: int = 900, span_m: float = 100.0) -> Image.Image:
    """One HDL-32E revolution starting at t, bird's-eye in the sensor frame, coloured by intensity."""
    from groundfloor import hdl32e
    from raysim.sensors.carrier import CarrierScene
    from raysim.sensors.lidar import LidarRenderer

    renderer = LidarRenderer(world, CarrierScene(world.scene_objects(), sea_material=material_index("sea")))
    n = int(round(hdl32e.cycles_per_revolution(renderer.cfg.rotation_hz) / 12)) * 12
    t = (int(t_s / hdl32e.CYCLE_DT_S) + np.arange(n)) * hdl32e.CYCLE_DT_S
    block = hdl32e.block_azimuth_centideg(t, renderer.cfg.rotation_hz)
    azimuth = hdl32e.decoder_azimuths_centideg(block.reshape(-1, 12)).reshape(-1, 32)
    points, _ = renderer.points(renderer.measure(t, block, azimuth))
    image = Image.new("RGB", (size_px, size_px), (8, 10, 16))
    scale = size_px / (2 * span_m)
    # sensor frame, bow up: image x = -y (left is left), image y = -x
    u = (size_px / 2 - points["y"] * scale).astype(int)
    v = (size_px / 2 - points["x"] * scale).astype(int)
    keep = (u >= 0) & (u < size_px) & (v >= 0) & (v < size_px)
    level = np.clip(points["intensity"][keep].astype(float) / 60.0, 0.0, 1.0)
    colour = np.stack([255 * level, 80 + 175 * (1 - np.abs(level - 0.5) * 2), 255 * (1 - level)], axis=1).astype(np.uint8)
    pixels = np.asarray(image).copy()
    pixels[v[keep], u[keep]] = colour
    image = Image.fromarray(pixels)
    draw = ImageDraw.Draw(image)
    for ring_m in (25, 50, 75, 100):
        r = ring_m * scale
        draw.ellipse([size_px / 2 - r, size_px / 2 - r, size_px / 2 + r, size_px / 2 + r], outline=(60, 60, 70))
        draw.text((size_px / 2 + 3, size_px / 2 - r + 2), f"{ring_m} m", fill=(120, 120, 130))
    draw.text((8, 8), f"HDL-32E, one revolution at t = {t_s:g} s, bow up, colour = reflectivity", fill=(200, 200, 200))
    return image


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("scenario", nargs="?", type=Path, default=REPO / "scenarios" / "busy_open_sea.yaml")
    parser.add_argument("--time", type=float, default=100.0, help="instant of the pictures, s")
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    world = World(scenario)
    scene = Scene(world.scene_objects(), sea=True, sea_material=material_index("sea"))
    top_view(world, scene, args.time).save(HERE / f"{scenario.name}_top.png", optimize=True)
    mast_view(world, scene, args.time).save(HERE / f"{scenario.name}_mast.png", optimize=True)
    lidar_sweep_view(world, args.time).save(HERE / f"{scenario.name}_lidar.png", optimize=True)


if __name__ == "__main__":
    main()
