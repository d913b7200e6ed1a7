"""A region named in a text that is no region of the explanation ('patch K9 of frame 2' when the grid has 7 columns,
'patch F6 of frame 5' of four frames, or 'the 8x8 patch at rows 26 to 33, ...' when the patches start at rows 24 and
32): contradicted. A region of the explanation is a name like any other (masked before this reads the text), so a
region phrase left in the masked text names nothing there."""

from __future__ import annotations

from xairl.narrators.verify.checks import Claim
from xairl.policies.region_names import REGION_RE


def unknown_regions(masked: str) -> list[Claim]:
    """A contradicted claim per region phrase of ``masked`` (the sentence with every known name masked)."""
    return [
        Claim(
            "feature",
            m.group(0),
            "contradicted",
            "no region of this explanation has this name (regions are "
            "named by a grid reference, 'patch F6 of frame 2': column letters from the left, row numbers from "
            "the top; or by their pixels, 'the 12x12 patch at rows 60 to 71, columns 60 to 71 of frame 2', "
            "counting rows, columns, channels and frames from 0)",
            "region.unknown",
        )
        for m in REGION_RE.finditer(masked)
    ]
