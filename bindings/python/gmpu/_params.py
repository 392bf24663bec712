"""The library's parameter table (gmpu_param_count / gmpu_param_info), read once at import:
names, keys, types, defaults, ranges and one-line docs all come from libgmpu, so a parameter
added to the C library appears here by itself."""
from __future__ import annotations

from typing import Dict, NamedTuple, Union

from ._errors import check
from ._library import ffi, lib

__all__ = ["ParamInfo", "PARAM_INFO", "PARAMS", "param_value"]


class ParamInfo(NamedTuple):
    """One row of the C library's parameter table."""
    key: int
    name: str
    integer: bool          #: only whole numbers are accepted
    switch: bool           #: an integer in 0..1, read back as a bool
    default: float         #: a new surface's value
    min: float
    max: float
    min_exclusive: bool
    max_exclusive: bool
    refits: bool           #: changing it discards a previous fit
    doc: str


def _read_table() -> Dict[str, ParamInfo]:
    table = {}
    info = ffi.new("gmpu_param_info_t *")
    for key in range(1, lib.gmpu_param_count() + 1):
        check(lib.gmpu_param_info(key, info), "gmpu_param_info")
        integer = info.type == lib.GMPU_TYPE_INT
        name = ffi.string(info.name).decode()
        table[name] = ParamInfo(key, name, integer, integer and info.min == 0 and info.max == 1,
                                float(info.default_value), float(info.min), float(info.max),
                                bool(info.min_exclusive), bool(info.max_exclusive), bool(info.refits),
                                ffi.string(info.doc).decode())
    return table


#: Every parameter of the library, by name (the keyword arguments of Surface and reconstruct).
PARAM_INFO: Dict[str, ParamInfo] = _read_table()
#: Parameter names → gmpu_param keys.
PARAMS: Dict[str, int] = {name: p.key for name, p in PARAM_INFO.items()}


def param_value(name: str, value: float) -> Union[int, float, bool]:
    """A value read from the library in the parameter's own Python type."""
    p = PARAM_INFO[name]
    if p.switch:
        return bool(value)
    if p.integer and float(value).is_integer():
        return int(value)
    return float(value)
