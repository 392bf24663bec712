"""The binding's parameters are the library's table (gmpu_param_count / gmpu_param_info):
names, keys, types, defaults and ranges are read from libgmpu, not restated."""
import math

import numpy as np
import pytest

import gmpu
from gmpu._library import ffi, lib


def test_params_are_every_key_of_the_library():
    assert list(gmpu.PARAMS.values()) == list(range(1, lib.gmpu_param_count() + 1))
    for name, key in gmpu.PARAMS.items():
        assert lib.gmpu_param_key(name.encode()) == key
        assert lib.gmpu_param_key(f"GMPU_PARAM_{name.upper()}".encode()) == key
        assert getattr(lib, f"GMPU_PARAM_{name.upper()}") == key  # the header's enumerator
    assert set(gmpu.PARAMS) == {n[len("GMPU_PARAM_"):].lower() for n in ffi.typeof("gmpu_param").relements}


def _sphere(n=300):
    v = np.random.default_rng(1).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_param_info_is_what_a_surface_does():
    points = _sphere()
    with gmpu.Surface(points) as s:
        for name, p in gmpu.PARAM_INFO.items():
            value = s.get_param(name)
            assert value == p.default, name
            assert type(value) is (bool if p.switch else int if p.integer else float), name
            assert len(p.doc) > 10 and p.min < p.max
    for name, p in gmpu.PARAM_INFO.items():
        with gmpu.Surface(points) as s:
            if not p.max_exclusive:
                s.set_params(**{name: p.max})
            with pytest.raises(gmpu.InvalidArgumentError, match=f"GMPU_PARAM_{name.upper()}"):
                s.set_params(**{name: math.nextafter(p.max, math.inf) if not p.integer else p.max + 1})


def test_unknown_parameter_names_the_librarys():
    with pytest.raises(TypeError, match="max_depth"):
        gmpu.Surface(_sphere(), no_such_parameter=1)
