"""The service's wire format besides JSON: msgpack (``content-type`` or ``accept: application/msgpack``), numpy arrays
as an extension, so that arrays travel without a round trip through text. Shared by the service and the client.

The layout (:data:`ND_LAYOUT`, what any msgpack library can read and write without pkm): an array is a msgpack
extension of type ``1`` whose payload is itself msgpack, an array of three entries ``[dtype, shape, data]``: ``dtype``
a numpy type string (``"<f8"``: little-endian float64; ``"<i8"``, ``"|b1"``...), ``shape`` an array of integers,
``data`` a bin of the entries' bytes in C order (row after row), ``prod(shape) * itemsize`` bytes. Plain msgpack
arrays of numbers are read as well; the answers' arrays come in this form (float64 where SI values, int64 counts).
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: The media type of a msgpack body.
MSGPACK = "application/msgpack"
#: The msgpack extension type of a numpy array.
ND_EXT = 1
#: The layout of that extension, in words (the schemas' descriptions and the OpenAPI description say it).
ND_LAYOUT = (f"In a msgpack body (application/msgpack) an array may be, and an answer's is, msgpack extension type "
             f"{ND_EXT}: its payload a msgpack array [dtype, shape, data], dtype a numpy type string ('<f8': "
             "little-endian float64), shape an array of integers, data a bin of the entries' bytes in C (row-major) "
             "order.")


def pack(obj: Any) -> bytes:
    """``obj`` as msgpack, numpy arrays as extension :data:`ND_EXT` (``[dtype, shape, bytes]``)."""
    import msgpack  # type: ignore[import-untyped]

    def default(x: Any) -> Any:
        if isinstance(x, np.ndarray):
            a = np.ascontiguousarray(x)
            return msgpack.ExtType(ND_EXT, msgpack.packb([a.dtype.str, list(a.shape), a.tobytes()]))
        if isinstance(x, np.generic):
            return x.item()
        raise TypeError(f"cannot pack {type(x).__name__}")

    return msgpack.packb(obj, default=default, use_bin_type=True)


def unpack(data: bytes) -> Any:
    """The inverse of :func:`pack` (a malformed extension is a ValueError)."""
    import msgpack  # type: ignore[import-untyped]

    def ext_hook(code: int, payload: bytes) -> Any:
        if code != ND_EXT:
            return msgpack.ExtType(code, payload)
        dtype, shape, raw = msgpack.unpackb(payload, raw=False)
        dt = np.dtype(dtype)
        if dt.kind not in "fiub" or int(np.prod(shape)) * dt.itemsize != len(raw):
            raise ValueError("a malformed array")
        return np.frombuffer(raw, dtype=dt).reshape(shape)

    return msgpack.unpackb(data, ext_hook=ext_hook, raw=False, max_bin_len=2**28,
                           max_array_len=10_000_000, max_map_len=10_000)



__all__ = ["MSGPACK", "ND_EXT", "ND_LAYOUT", "pack", "unpack"]
