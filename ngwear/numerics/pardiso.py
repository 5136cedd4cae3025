"""Intel MKL PARDISO (from the ``mkl`` wheel) for a symmetric positive definite K, with its Schur complement.

PARDISO orders K by METIS nested dissection and factorises it supernodally with the BLAS-3 kernels
of MKL, in parallel.  Given a set c of rows (``schur``) it orders them last, stops the factorisation
there and hands back the dense Schur complement S = K_cc − K_ci K_ii⁻¹ K_ic; a solve is then the
forward substitution on the interior (phase 331), a dense solve with S on c, and the backward
substitution (phase 333), so K⁻¹ and S come out of one factorisation.  The binding follows MKL's
``pardiso`` interface (0-based CSR of the upper triangle, 32-bit indices); pypardiso, the usual
wrapper, does not pass the Schur complement through.

Without Schur rows the factorisation hands back its fill-in reducing ordering (:attr:`Pardiso.ordering`, METIS's,
``iparm[4] = 2``); a matrix of the same graph (a geometry update's K) factorises with it given (``iparm[4] = 1``)
and skips METIS, a part of every factorisation (``benchmarks/update_factor.py`` measures it); a factorisation given METIS's
ordering is METIS's to the bit.
"""
from __future__ import annotations

import ctypes
import glob
import os
import sys
import weakref
from pathlib import Path

import numpy as np
import scipy.sparse as sp

_INT = ctypes.POINTER(ctypes.c_int32)


def _library() -> ctypes.CDLL:
    """MKL's single dynamic library, as the ``mkl`` wheel installs it into the environment's lib/.

    Its OpenMP threads go to sleep at once after a call (``KMP_BLOCKTIME=0`` unless set): by default
    they spin for 200 ms, which starves the NumPy work between the many back-substitutions of the
    matrix-free contact solve.
    """
    os.environ.setdefault("KMP_BLOCKTIME", "0")
    candidates = sorted(glob.glob(str(Path(sys.prefix) / "lib" / "libmkl_rt.so*")), key=len)
    for path in candidates + ["libmkl_rt.so.2", "libmkl_rt.so"]:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        lib.MKL_Set_Num_Threads_Local.restype = ctypes.c_int
        lib.MKL_Set_Num_Threads_Local.argtypes = [ctypes.c_int]
        lib.pardiso.restype = None
        lib.pardiso.argtypes = [ctypes.POINTER(ctypes.c_int64), _INT, _INT, _INT, _INT, _INT, ctypes.c_void_p,
                                _INT, _INT, _INT, _INT, _INT, _INT, ctypes.c_void_p, ctypes.c_void_p, _INT]
        return lib
    raise ImportError("MKL PARDISO not found: pip install mkl")


_MKL = None


class Pardiso:
    """Cholesky factorisation of an SPD sparse matrix K (both triangles given); optional Schur rows.

    With ``schur`` rows, ``schur_upper`` holds S as PARDISO hands it back (row-major, upper triangle
    valid, the rest undefined; no copies of an n_c × n_c matrix are made) and ``schur_complement``
    builds the whole symmetric S from it; without, both are None.  Without, ``ordering`` (a permutation of the
    rows, from an earlier factorisation's :attr:`ordering`) replaces METIS's; with, it must be None.
    """

    def __init__(self, K: sp.spmatrix, schur: np.ndarray | None = None, ordering: np.ndarray | None = None):
        global _MKL
        _MKL = _MKL or _library()
        upper = sp.triu(K, format="csr")
        upper.sort_indices()
        self.n = K.shape[0]
        self._a = np.ascontiguousarray(upper.data, dtype=np.float64)
        self._ia = upper.indptr.astype(np.int32)
        self._ja = upper.indices.astype(np.int32)
        self._pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self.iparm[[0, 1, 17, 34]] = 1, 3, -1, 1  # own settings, parallel METIS, report nnz(L), 0-based
        self._perm = np.zeros(self.n, dtype=np.int32)
        weakref.finalize(self, _release, self._pt, self.iparm)
        self.schur = np.zeros(0, dtype=int) if schur is None else np.sort(np.asarray(schur, dtype=int))
        self.schur_upper = None
        self.ordering = None                       # the fill-in reducing ordering used (none with Schur rows)
        if ordering is not None and len(self.schur):
            raise ValueError("Pardiso: an ordering cannot be given with Schur rows")
        if len(self.schur):
            self._perm[self.schur] = 1
            self.iparm[35] = 2                     # Schur complement + partial solves
            self.schur_upper = np.zeros((len(self.schur), len(self.schur)))
            self._call(12, np.zeros(self.n), self.schur_upper)
        else:
            self.iparm[4] = 2 if ordering is None else 1           # hand METIS's ordering back, or take the given
            if ordering is not None:
                self._perm[:] = ordering
            self._call(12, np.zeros(self.n), np.zeros(self.n))
            self.ordering = self._perm

    def _call(self, phase: int, b: np.ndarray, x: np.ndarray) -> None:
        nrhs = 1 if b.ndim == 1 else b.shape[1]
        err = ctypes.c_int32(0)
        i32 = lambda v: ctypes.byref(ctypes.c_int32(v))  # noqa: E731
        _MKL.pardiso(self._pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), i32(1), i32(1), i32(2), i32(phase),
                     i32(self.n), self._a.ctypes.data, self._ia.ctypes.data_as(_INT), self._ja.ctypes.data_as(_INT),
                     self._perm.ctypes.data_as(_INT), i32(nrhs), self.iparm.ctypes.data_as(_INT), i32(0),
                     b.ctypes.data, x.ctypes.data, ctypes.byref(err))
        if err.value != 0:
            raise RuntimeError(f"MKL PARDISO phase {phase} failed with error {err.value}")

    def solve(self, rhs: np.ndarray, schur_solve=None) -> np.ndarray:
        """K⁻¹ rhs (1D or columns); with Schur rows, ``schur_solve`` applies S⁻¹ between the substitutions.

        The substitutions run on one thread: they are memory-bound, and a team of OpenMP threads that
        must meet at every supernode only waits for a busy core.
        """
        b = np.asfortranarray(rhs, dtype=np.float64)
        x = np.zeros_like(b)
        threads = _MKL.MKL_Set_Num_Threads_Local(1)
        try:
            if not len(self.schur):
                self._call(33, b, x)
                return np.ascontiguousarray(x)
            self._call(331, b, x)
            x[self.schur] = schur_solve(x[self.schur])
            self.iparm[5] = 1                      # backward substitution in place
            self._call(333, x, np.zeros_like(b))
            return np.ascontiguousarray(x)
        finally:
            self.iparm[5] = 0
            _MKL.MKL_Set_Num_Threads_Local(threads)

    @property
    def schur_complement(self) -> np.ndarray | None:
        """S, both triangles (a new array)."""
        if self.schur_upper is None:
            return None
        return np.triu(self.schur_upper) + np.triu(self.schur_upper, 1).T

    @property
    def factor_nonzeros(self) -> int:
        """Nonzeros of the Cholesky factor (MKL's iparm[17])."""
        return int(self.iparm[17])


def _release(pt: np.ndarray, iparm: np.ndarray) -> None:
    """Phase −1: free PARDISO's memory for the handle ``pt``."""
    if pt.any():
        err, one = ctypes.c_int32(0), ctypes.c_int32(1)
        _MKL.pardiso(pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)), ctypes.byref(one), ctypes.byref(one),
                     ctypes.byref(ctypes.c_int32(2)), ctypes.byref(ctypes.c_int32(-1)), ctypes.byref(one), None, None,
                     None, None, ctypes.byref(one), iparm.ctypes.data_as(_INT), ctypes.byref(ctypes.c_int32(0)), None,
                     None, ctypes.byref(err))
