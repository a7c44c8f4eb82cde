"""A run's map quality as the one line ``slamtrials trial`` prints (:class:`slamtrials.metric.mapquality.MapQuality`)."""

from __future__ import annotations

from slamtrials.metric.mapquality import MapQuality

__all__ = ["map_quality_text"]


def _share(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"


def map_quality_text(quality: MapQuality | None) -> str:
    """``map: walls precision 0.70 / 0.87, recall 0.86 / 0.95 (within 1 / 2 cells of 0.05 m); free IoU 0.94;
    ghost 2.3 m^2 (alignment rms 0.094 m)``; ``map: not scored`` for None."""
    if quality is None:
        return "map: not scored (no map)"
    rms = "" if quality.alignment_rms_m is None else f" (alignment rms {quality.alignment_rms_m:.3f} m)"
    return (
        f"map: walls precision {_share(quality.occupied_precision_1)} / {_share(quality.occupied_precision_2)}, "
        f"recall {_share(quality.occupied_recall_1)} / {_share(quality.occupied_recall_2)} (within 1 / 2 cells of "
        f"{quality.cell_m:g} m); free IoU {_share(quality.free_iou)}; ghost {quality.ghost_free_m2:.1f} m^2{rms}"
    )
