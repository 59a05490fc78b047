"""The last guard of every writer: no non-finite number reaches an output file.

Writers (VTK, save files, history CSV) call ``require_finite(name, values)`` on each numeric
array before anything is written; a NaN or an infinity is refused with an error naming the
field, its first bad row and value, and nothing is written. The engine already stops a run
that becomes unstable and puts the model back (``physics.rigid``), so this should never fire;
it is there so that no other path can write one either.
"""
from __future__ import annotations

import numpy as np

from dec3d.errors import Dec3dError


class NonFiniteOutputError(Dec3dError):
    """An output would hold NaN or an infinity."""


#: fields in which NaN is a declared marker, not a number (infinities are still refused):
#: the residual-friction column of a contact's property row (``kernels.jointlaw``: NaN = the
#: peak friction). A save file writes them as 0 with a mask beside the array (``io.state``,
#: ``nan_masks``), and a restore puts the NaN back, so a restored run continues bit for bit
NAN_MARKERS = {"contacts.prop"}


def require_finite(name: str, values, missing_ok: bool = False) -> None:
    """Raise ``NonFiniteOutputError`` naming ``name`` when ``values`` (a number or an array)
    holds a NaN or an infinity; integers, booleans and strings always pass. ``missing_ok``:
    NaN stands for "no value" and the writer leaves it out (an empty CSV cell), so only
    infinities are refused."""
    a = np.asarray(values)
    if a.dtype.kind not in "fc" or a.size == 0:
        return
    ok = ~np.isinf(a) if (missing_ok or name in NAN_MARKERS) else np.isfinite(a)
    if ok.all():
        return
    first = np.unravel_index(int(np.flatnonzero(~ok.ravel())[0]), a.shape)
    where = f" at row {first[0]}" if a.ndim else ""
    raise NonFiniteOutputError(f"refusing to write '{name}': it holds a non-finite value "
                               f"({a[first].item()!r}{where}); nothing was written")
