"""A measured line cut to ``profile-file``'s ``region`` as it is read, as a map is to its own
(``map_pipeline.crop``): the points it leaves out are neither refused nor filled, and the
levelling and every caveat see only the points it keeps."""

from __future__ import annotations

import numpy as np

from .map_pipeline import check_still_periodic, crop, undefined_in_region
from .profile_file import MIN_POINTS, fill_table


def crop_line(z: np.ndarray, dx: float, p, where: str, periodic: bool, summary: dict, instrument: bool) -> np.ndarray:
    """The points of ``z`` (spaced ``dx``) that ``p.region`` keeps, its undefined points (NaN) inside
    refused (an instrument file's; a table's are named by ``check_finite``) or filled (``undefined:
    harmonic``) from the region's own points; ``summary`` told of the crop and of those points."""
    from .instrument_file import undefined_message

    if periodic:  # its last point is no longer followed by its first
        check_still_periodic((dx, dx), p, where, "line")
    holes = np.isnan(z)
    kept, summary["region_pixels"] = crop(z, (dx, dx), p.region, where)
    if kept.size < MIN_POINTS:
        raise ValueError(f"{where}: region.x keeps {kept.size} points of the line; at least {MIN_POINTS} are needed")
    if missing := int(np.count_nonzero(holes)):
        said = undefined_in_region(holes, missing, (dx, dx), p, where)
        if instrument and p.undefined == "refuse" and said["undefined_points"]:
            raise ValueError(undefined_message(where, said["undefined_points"], kept.size, " of the region"))
        fill_table(where, kept, p)  # undefined: harmonic, in place
        # an instrument file's caveat of its filled points is the whole file's: the region's replaces it
        caveats = [*([] if instrument else summary.get("caveats", ())), *said.pop("caveats")]
        summary.update(said, **({"caveats": caveats} if caveats else {}))
    return kept
