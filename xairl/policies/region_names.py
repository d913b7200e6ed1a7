"""How an image's pixels are named in regions: the grid of square patches (:func:`region_size`), each patch's name
('patch F6 of frame 2', :data:`REGION_FORMAT`) and extent in words (:data:`REGION_EXTENT`), the pattern a text's
region phrase matches (:data:`REGION_RE`), and :func:`patches`, a user's own grid of an image's columns."""

from __future__ import annotations

import re
from collections.abc import Sequence

import numpy as np


def patches(shape: Sequence[int], size: int | Sequence[int], prefix: str = "patch") -> dict[str, np.ndarray]:
    """Groups of an image's flat columns: one group per ``size`` x ``size`` patch over all channels.

    :param shape: the image, (C, H, W) or (H, W); patches at the edges are smaller when ``size`` does not divide.
    :returns: ``{"patch[r,c]": column indices}`` in row-major patch order, for :meth:`Explanation.grouped`.
    """
    shape = tuple(int(s) for s in shape)
    c, h, w = (1, *shape) if len(shape) == 2 else shape
    ph, pw = (size, size) if isinstance(size, int) else tuple(size)
    idx = np.arange(c * h * w).reshape(c, h, w)
    return {
        f"{prefix}[{r // ph},{q // pw}]": idx[:, r : r + ph, q : q + pw].ravel()
        for r in range(0, h, ph)
        for q in range(0, w, pw)
    }


#: how a region is named: a grid reference, 'patch F6' (column letters from the left, A first; row numbers from the
#: top, 1 first, as on a map or a spreadsheet), then ' of frame 2' (a frame stack) or ' of channel 2' in an image of
#: several channels (counting from 0, as in the pixels' names 'obs[2,60,60]'), then ' of KEY' in a dict of several
#: inputs. The pixels a region covers are its extent (:data:`REGION_EXTENT`, :meth:`Observation.region_extents`).
REGION_FORMAT = "patch {ref}"
#: the pixels a region covers in words: 'the 12x12 patch at rows 60 to 71, columns 60 to 71' (rows and columns count
#: from 0), then the channel or frame and the key as in its name; a text may name a region so too
REGION_EXTENT = "the {h}x{w} patch at rows {r0} to {r1}, columns {c0} to {c1}"
#: any phrase shaped like a region's name (:data:`REGION_FORMAT`, capital letters) or its extent
#: (:data:`REGION_EXTENT`, or close to it: 'rows 3-8')
_SPAN = r"\d+(?:\s*(?:to|-|–|through)\s*\d+)?"
_LAYER = r"(?:\s+(?:of|in)\s+(?:the\s+)?(?:channel|frame)\s+\d+)?"
REGION_RE = re.compile(
    rf"\b(?:(?i:(?:\d+\s*[x×]\s*\d+\s+)?(?:patch|region|block)\s+(?:at|spanning|covering|over)\s+"
    rf"rows?\s+{_SPAN}\s*,?\s*(?:and\s+)?columns?\s+{_SPAN}{_LAYER})"
    rf"|(?i:patch)\s+[A-Z]{{1,3}}[1-9]\d{{0,3}}\b(?i:{_LAYER}))"
)


def region_size(h: int, w: int) -> int:
    """The side of a region's square patch in an h x w image: about a tenth of the longer side (at most ~100 patches
    per channel), rounded up to a divisor of both sides when one is near (64 -> 8, 84 -> 12), so patches are even."""
    target = max(1, -(-max(h, w) // 10))
    even = [s for s in range(target, 2 * target + 1) if h % s == 0 and w % s == 0]
    return even[0] if even else target


def grid_ref(row: int, column: int) -> str:
    """A patch's grid reference from its row and column among the patches (from 0): (5, 5) -> 'F6', (0, 26) ->
    'AA1'."""
    letters, c = "", column + 1
    while c:
        c, rest = divmod(c - 1, 26)
        letters = chr(ord("A") + rest) + letters
    return f"{letters}{row + 1}"


def region_name(
    row: int, column: int, channel: int | None = None, key: str | None = None, layer: str = "channel"
) -> str:
    """A region's name (:data:`REGION_FORMAT`) from its row and column among the patches (from 0): 'patch F6 of
    frame 2'; ``layer`` is 'channel' or 'frame'."""
    name = REGION_FORMAT.format(ref=grid_ref(row, column))
    return name + (f" of {layer} {channel}" if channel is not None else "") + (f" of {key}" if key else "")


def region_extent(
    rows: tuple[int, int],
    columns: tuple[int, int],
    channel: int | None = None,
    key: str | None = None,
    layer: str = "channel",
) -> str:
    """The pixels a region covers in words (:data:`REGION_EXTENT`), from its first and last row and column."""
    name = REGION_EXTENT.format(
        h=rows[1] - rows[0] + 1, w=columns[1] - columns[0] + 1, r0=rows[0], r1=rows[1], c0=columns[0], c1=columns[1]
    )
    return name + (f" of {layer} {channel}" if channel is not None else "") + (f" of {key}" if key else "")
