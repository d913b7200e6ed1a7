"""A region named in a text that is no region of the explanation ('the 8x8 patch at rows 26 to 33, ...' when the
patches start at rows 24 and 32): contradicted. A region of the explanation is a name like any other (masked before
this reads the text), so a region phrase left in the masked text names nothing there."""
from __future__ import annotations

from ...observation import REGION_RE
from .checks import Claim


def unknown_regions(masked: str) -> list[Claim]:
    """A contradicted claim per region phrase of ``masked`` (the sentence with every known name masked)."""
    return [Claim("feature", m.group(0), "contradicted", "no region of this explanation has these rows, columns and "
                  "channel (regions are named as 'the 8x8 patch at rows 0 to 7, columns 0 to 7 of channel 0', "
                  "counting from 0)", "region.unknown") for m in REGION_RE.finditer(masked)]
