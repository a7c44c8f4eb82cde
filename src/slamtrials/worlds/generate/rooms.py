"""Clean the painted label image: split rooms cut in pieces, merge slivers into their neighbours.

Corridors painted over room strips can cut a room in two or leave a sliver of it; a sliver too small
or too thin to be a room joins the neighbour it shares the longest boundary with (which may be the
circulation, where it becomes an alcove).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from slamtrials.worlds.generate.raster import OUTSIDE, Grid

__all__ = ["clean_labels", "merge_room", "neighbour_of", "room_boxes", "grow_box", "Box"]

Box = tuple[slice, slice]


def grow_box(box: Box, by: int, shape: tuple[int, int]) -> Box:
    """The box enlarged by ``by`` cells on every side, clipped to ``shape``."""
    rows, cols = box
    return (
        slice(max(0, rows.start - by), min(shape[0], rows.stop + by)),
        slice(max(0, cols.start - by), min(shape[1], cols.stop + by)),
    )


def _union(a: Box, b: Box) -> Box:
    return (
        slice(min(a[0].start, b[0].start), max(a[0].stop, b[0].stop)),
        slice(min(a[1].start, b[1].start), max(a[1].stop, b[1].stop)),
    )


def room_boxes(labels: NDArray[np.int32]) -> dict[int, Box]:
    """Bounding boxes of every label >= 2 present in the image."""
    objects = ndimage.find_objects(labels)
    return {i + 1: box for i, box in enumerate(objects) if box is not None and i + 1 >= 2}


def neighbour_of(labels: NDArray[np.int32], label: int, box: Box) -> int:
    """The label sharing the longest boundary with ``label`` (non-outside preferred)."""
    big = grow_box(box, 1, labels.shape)
    window = labels[big]
    mask = window == label
    ring = ndimage.binary_dilation(mask, structure=ndimage.generate_binary_structure(2, 1)) & ~mask
    counts = np.bincount(window[ring], minlength=2)
    counts[OUTSIDE] = 0
    if label < len(counts):
        counts[label] = 0
    return int(np.argmax(counts)) if counts.max() > 0 else OUTSIDE


def merge_room(labels: NDArray[np.int32], boxes: dict[int, Box], label: int, into: int) -> None:
    """Relabel room ``label`` as ``into`` in place, keeping ``boxes`` up to date."""
    box = boxes.pop(label)
    window = labels[box]
    window[window == label] = into
    if into >= 2 and into in boxes:
        boxes[into] = _union(boxes[into], box)


def _trim_thin(labels: NDArray[np.int32], boxes: dict[int, Box], size: int) -> None:
    """Turn every part of a room that a ``size x size`` square cannot sweep into solid (OUTSIDE)."""
    for label, box in boxes.items():
        window = labels[box]
        mask = (window == label).view(np.uint8)
        opened = ndimage.maximum_filter(
            ndimage.minimum_filter(mask, size=size, mode="constant", cval=0), size=size, mode="constant", cval=0
        )
        window[(mask > opened)] = OUTSIDE


def _split_pieces(labels: NDArray[np.int32], uses: list[tuple[str, str]], boxes: dict[int, Box]) -> None:
    """Give every 4-connected piece of a room but the largest a label of its own."""
    four = ndimage.generate_binary_structure(2, 1)
    for label in sorted(boxes):
        box = boxes[label]
        window = labels[box]
        parts, count = ndimage.label(window == label, structure=four)
        if count == 0:
            del boxes[label]
            continue
        sizes = np.bincount(parts.ravel())[1:]
        keep = int(np.argmax(sizes)) + 1
        for part in range(1, count + 1):
            rows, cols = np.nonzero(parts == part)
            sub = (
                slice(box[0].start + rows.min(), box[0].start + rows.max() + 1),
                slice(box[1].start + cols.min(), box[1].start + cols.max() + 1),
            )
            if part == keep:
                boxes[label] = sub
                continue
            new = len(uses) + 2
            uses.append(uses[label - 2])
            window[parts == part] = new
            boxes[new] = sub


def clean_labels(
    labels: NDArray[np.int32], uses: list[tuple[str, str]], grid: Grid, *, min_area: float = 2.5, min_width: float = 1.2
) -> dict[int, Box]:
    """Make every room a clean, reachable shape.

    Parts of a room narrower than ``min_width`` metres (slivers left by corridors painted over room
    strips, thin legs) become solid, so no passage narrower than that can lead into or through a room;
    rooms cut in pieces get one label per piece; pieces smaller than ``min_area`` m^2 join the
    neighbour they share the longest boundary with. Modifies ``labels`` and ``uses`` in place; returns
    the bounding box of every room label left.
    """
    boxes = room_boxes(labels)
    _trim_thin(labels, boxes, 2 * (int(round(min_width / grid.resolution)) // 2) + 1)
    _split_pieces(labels, uses, boxes)
    min_px = min_area / grid.resolution**2
    order = sorted(boxes, key=lambda k: (int(np.count_nonzero(labels[boxes[k]] == k)), k))
    for label in order:
        box = boxes[label]
        if int(np.count_nonzero(labels[box] == label)) < min_px:
            merge_room(labels, boxes, label, neighbour_of(labels, label, box))
    return boxes
