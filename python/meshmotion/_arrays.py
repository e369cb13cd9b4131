"""Arrays a caller gives to the Python layer: converted exactly into what the library reads, or
refused with the dtype found. Never truncated (a float index), never half-read (a complex
coordinate)."""

import numpy as _np

from ._core import InputError

_EXACT_IN_FLOAT64 = 2**53


def real_array(array, what):
    """A C-contiguous float64 copy of `array`, whose dtype must be a float of at most 64 bits or an
    integer (whose values then fit float64 exactly)."""
    a = _np.asarray(array)
    if a.size == 0:
        return _np.ascontiguousarray(a, dtype=_np.float64)
    if a.dtype.kind == "f" and a.dtype.itemsize <= 8:
        return _np.ascontiguousarray(a, dtype=_np.float64)
    if a.dtype.kind in "iu":
        if a.dtype.itemsize == 8 and _np.abs(a.astype(_np.float64)).max() > _EXACT_IN_FLOAT64:
            raise InputError(f"{what}: integer values beyond 2**53 do not convert exactly to float64")
        return _np.ascontiguousarray(a, dtype=_np.float64)
    raise InputError(f"{what}: expected real numbers (got dtype {a.dtype})")


def index_array(array, what):
    """A C-contiguous int64 copy of `array`, whose dtype must be an integer: a float index is
    refused, not rounded."""
    a = _np.asarray(array)
    if a.size == 0:
        return _np.ascontiguousarray(a, dtype=_np.int64)
    if a.dtype.kind not in "iu":
        raise InputError(f"{what}: expected integer indices (got dtype {a.dtype}; a float index is not rounded)")
    if a.dtype == _np.uint64 and a.max() > _np.iinfo(_np.int64).max:
        raise InputError(f"{what}: index {a.max()} is beyond int64")
    return _np.ascontiguousarray(a, dtype=_np.int64)
