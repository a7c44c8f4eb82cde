"""Write a :class:`World` as a ROS map_server map: a PNG image plus a YAML file.

The YAML holds the standard keys (image, resolution, origin, negate, occupied_thresh, free_thresh) and
a ``slamtrials`` block with the world's name, start pose and metadata, which map_server ignores and
:func:`slamtrials.worlds.formats.rosmap.load_rosmap` reads back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml
from PIL import Image

from slamtrials.atomicfile import atomic_write, atomic_write_text
from slamtrials.worlds.world import World

__all__ = ["save_rosmap"]

FREE_GREY = 254
OCCUPIED_GREY = 0


def save_rosmap(world: World, yaml_path: str | Path, image_name: str | None = None) -> Path:
    """Write ``world`` to ``yaml_path`` and its image (PNG, free 254 / occupied 0) beside it.

    Returns the path of the YAML file. Both files are written atomically.
    """
    yaml_path = Path(yaml_path)
    image_name = image_name or yaml_path.with_suffix(".png").name
    grey = np.where(world.occupied, OCCUPIED_GREY, FREE_GREY).astype(np.uint8)
    atomic_write(
        yaml_path.parent / image_name, lambda h: Image.fromarray(grey, mode="L").save(h, format="PNG", optimize=True)
    )
    doc = {
        "image": image_name,
        "resolution": float(world.resolution),
        "origin": [float(v) for v in world.origin],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
        "slamtrials": {
            "name": world.name,
            "start": [round(float(v), 6) for v in world.start],
            "metadata": world.metadata,
        },
    }
    text = yaml.safe_dump(doc, sort_keys=False)
    atomic_write_text(yaml_path, text)
    return yaml_path
