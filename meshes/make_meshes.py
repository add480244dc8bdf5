"""Write the small shipped mesh assets next to this script.

- ``odin.glb``: the own ship Odin (10.9 m long, 3.5 m beam), :func:`raysim.meshes.own_ship`;
- ``pier.glb``: a 60 m x 8 m concrete pier, :func:`raysim.meshes.pier`.

Run from anywhere: ``python meshes/make_meshes.py``. Each file is written atomically
(temporary name, then rename). Geometries are named after their materials, so
:func:`raysim.meshes.load_mesh` restores the per-triangle materials.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # run from a source checkout without installing

from raysim.meshes import BodyMesh, own_ship, pier  # noqa: E402

ODIN_LENGTH_M = 10.9  # own ship Odin (thesis scenario, scenarios/busy_open_sea.yaml)
ODIN_BEAM_M = 3.5


def write_glb(mesh: BodyMesh, path: Path) -> int:
    """Write ``mesh`` as binary glTF (one geometry per material) atomically; return bytes."""
    data = mesh.to_scene().export(file_type="glb")
    fd, tmp = tempfile.mkstemp(prefix=path.name + ".", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
        os.chmod(tmp, 0o644)  # mkstemp creates 0600; assets are ordinary readable files
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
    return len(data)


def main() -> None:
    """Generate and write all shipped assets."""
    assets = {
        "odin.glb": own_ship(ODIN_LENGTH_M, ODIN_BEAM_M),
        "pier.glb": pier(),
    }
    for file_name, mesh in assets.items():
        size = write_glb(mesh, HERE / file_name)
        print(f"{file_name}: {mesh.n_triangles} triangles, {size} bytes")


if __name__ == "__main__":
    main()
