"""mpmvv's manufactured and exact solutions from Python: numpy arrays in and
out, over the same shared library as the C interface (libmpmvv-mms,
mpmvv_mms.h), found through ctypes where cmake --install put it.

    import numpy as np, mpmvv
    ring = mpmvv.Solution("ring", amplitude=0.5)
    X = np.array([[1.0, 0.0], [0.8, 0.5]])
    b = ring.body_force(X, t=0.25)          # (n, 2) [m/s^2]
    f = ring.fields(X, t=0.25)              # dict: position, displacement, velocity, acceleration (n, 2),
                                            # F, cauchy_stress, first_piola (n, 2, 2), F33, cauchy_stress_33 (n,)
    mpmvv.solutions(), mpmvv.parameters("ring")
"""
import ctypes
from pathlib import Path

import numpy as np

from ._library import LIBRARY

_lib = ctypes.CDLL(str((Path(__file__).resolve().parent / LIBRARY).resolve()))
_double_p = ctypes.POINTER(ctypes.c_double)


class _Fields(ctypes.Structure):
    # mpmvv_mms_fields, member for member
    _fields_ = [(name, _double_p) for name in ("position", "displacement", "velocity", "acceleration", "F", "F33",
                                               "cauchy_stress", "cauchy_stress_33", "first_piola", "body_force")]


_WIDTH = {"position": 2, "displacement": 2, "velocity": 2, "acceleration": 2, "F": 4, "F33": 1,
          "cauchy_stress": 4, "cauchy_stress_33": 1, "first_piola": 4, "body_force": 2}

_lib.mpmvv_mms_count.restype = ctypes.c_int
for _name in ("mpmvv_mms_name", "mpmvv_mms_summary"):
    getattr(_lib, _name).restype = ctypes.c_char_p
    getattr(_lib, _name).argtypes = [ctypes.c_int]
_lib.mpmvv_mms_manufactured.argtypes = [ctypes.c_int]
_lib.mpmvv_mms_parameter_count.argtypes = [ctypes.c_char_p]
_lib.mpmvv_mms_parameter.argtypes = [ctypes.c_char_p, ctypes.c_int] + [ctypes.POINTER(ctypes.c_char_p)] * 3
_lib.mpmvv_mms_create.restype = ctypes.c_void_p
_lib.mpmvv_mms_create.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.POINTER(ctypes.c_char_p)]
_lib.mpmvv_mms_destroy.argtypes = [ctypes.c_void_p]
_lib.mpmvv_mms_last_error.restype = ctypes.c_char_p
_lib.mpmvv_mms_axisymmetric.argtypes = [ctypes.c_void_p]
_lib.mpmvv_mms_density.restype = ctypes.c_double
_lib.mpmvv_mms_density.argtypes = [ctypes.c_void_p]
_lib.mpmvv_mms_evaluate.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_size_t, _double_p,
                                    ctypes.POINTER(_Fields)]
_lib.mpmvv_mms_body_force.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_size_t, _double_p, _double_p]


def _error():
    return _lib.mpmvv_mms_last_error().decode()


def solutions():
    """Every solution: its name, summary and whether a manufactured body force moves it."""
    return [{"name": _lib.mpmvv_mms_name(i).decode(), "summary": _lib.mpmvv_mms_summary(i).decode(),
             "manufactured": bool(_lib.mpmvv_mms_manufactured(i))} for i in range(_lib.mpmvv_mms_count())]


def parameters(name):
    """The solution's parameters as (key, default as text, meaning with unit)."""
    count = _lib.mpmvv_mms_parameter_count(name.encode())
    if count < 0:
        raise ValueError(f"unknown solution '{name}'")
    out = []
    for i in range(count):
        texts = [ctypes.c_char_p() for _ in range(3)]
        _lib.mpmvv_mms_parameter(name.encode(), i, *[ctypes.byref(t) for t in texts])
        out.append(tuple(t.value.decode() for t in texts))
    return out


def _text(value):
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return "[" + ",".join(_text(v) for v in value) + "]"
    return repr(value)


class Solution:
    """The solution `name` with settings as keyword arguments (the scene's keys, `mpmvv mms list`)."""

    def __init__(self, name, **settings):
        texts = [f"{key}={_text(value)}".encode() for key, value in settings.items()]
        array = (ctypes.c_char_p * max(len(texts), 1))(*texts)
        handle = _lib.mpmvv_mms_create(name.encode(), len(texts), array)
        if not handle:
            raise ValueError(_error())
        self._handle = handle
        self.name = name
        self.axisymmetric = bool(_lib.mpmvv_mms_axisymmetric(handle))
        self.density = _lib.mpmvv_mms_density(handle)

    def __del__(self):
        if getattr(self, "_handle", None):
            _lib.mpmvv_mms_destroy(self._handle)
            self._handle = None

    @staticmethod
    def _points(X):
        X = np.ascontiguousarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != 2:
            raise ValueError(f"reference points are an (n, 2) array, not {X.shape}")
        return X

    def body_force(self, X, t):
        """b = a - Div P / rho_0 at the reference points X [(n, 2)] at time t, the runs' own force."""
        X = self._points(X)
        b = np.empty_like(X)
        if _lib.mpmvv_mms_body_force(self._handle, float(t), X.shape[0], X.ctypes.data_as(_double_p),
                                     b.ctypes.data_as(_double_p)) != 0:
            raise ValueError(_error())
        return b

    def fields(self, X, t, names=tuple(_WIDTH)):
        """The exact fields at X and t, each an array of n rows (tensors (n, 2, 2), row-major)."""
        X = self._points(X)
        n = X.shape[0]
        arrays = {name: np.empty((n, _WIDTH[name])) for name in names}
        out = _Fields(**{name: a.ctypes.data_as(_double_p) for name, a in arrays.items()})
        if _lib.mpmvv_mms_evaluate(self._handle, float(t), n, X.ctypes.data_as(_double_p), ctypes.byref(out)) != 0:
            raise ValueError(_error())
        shapes = {1: (n,), 2: (n, 2), 4: (n, 2, 2)}
        return {name: a.reshape(shapes[_WIDTH[name]]) for name, a in arrays.items()}
