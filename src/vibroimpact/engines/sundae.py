"""Workarounds for scikit-sundae 1.2.0 shared by the SUNDIALS engines (see ``../shared/NOTES.md``), and a direct
binding to the CVODE that scikit-sundae ships, for callbacks compiled by numba.

scikit-sundae calls Python for every right-hand side and every event function evaluation; its wrapper alone costs
~2.5 us per call, ~200 calls per excitation period of the impact problem. :class:`CompiledCvode` drives the same
SUNDIALS 7 CVODE library (the shared objects in the ``scikit_sundae.libs`` folder of the wheel) through ``ctypes``,
with C function pointers (numba ``cfunc``) as callbacks: Python runs only between events. The binding checks the
ABI facts it relies on (SUNDIALS major version 7, 32-bit ``sunindextype``, the serial vector's layout) when it
loads; :func:`compiled_cvode_problem` names the first that fails, and the engines then fall back to scikit-sundae.
"""

from __future__ import annotations

import ctypes as C
import glob
import io
import os
import sys
import threading
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from functools import lru_cache
from typing import Any

import numpy as np
from numba import types
from numba.extending import intrinsic
from numpy.typing import NDArray

__all__ = ["clear_event_records", "solver_messages", "CompiledCvode", "compiled_cvode_problem", "content_data", "as_doubles", "evaluate_compiled"]

_ADAMS, _BDF, _NORMAL = 1, 2, 1
#: CVODE's return flags for a stop at ``tstop`` and at a root.
TSTOP_RETURN, ROOT_RETURN = 1, 2
#: Byte offset of ``data`` in SUNDIALS 7's ``_N_VectorContent_Serial`` {sunindextype length; int own_data; double *data}
#: and ``_SUNMatrixContent_Dense`` {sunindextype M, N; double *data; ...} with a 32-bit sunindextype (both checked)
_DATA_OFFSET = 8


def clear_event_records(events: Any) -> None:
    """Forget the roots recorded on a scikit-sundae event function.

    The records accumulate across ``init_step`` calls and every ``step`` rebuilds its result from all of them, so a
    long run gets slower step by step unless they are cleared after each event. They are private attributes in
    1.2.0 (``_i``, ``_t``, ``_y``, ``_i_cnt``, and for IDA ``_yp``, which alone made a 300 s compliant sweep 10x
    slower); if a later version renames them, this does nothing.
    """
    for name in ("_i", "_t", "_y", "_yp"):
        records = getattr(events, name, None)
        if records is not None:
            records.clear()
    counts = getattr(events, "_i_cnt", None)
    if counts is not None:
        counts[:] = 0


class _ThreadsOwnOutput(io.TextIOBase):
    """``sys.stdout`` while solver calls run (:func:`solver_messages`): what a thread inside such a call writes goes to
    that call's buffer, what any other thread writes goes on to the stream it replaced."""

    def __init__(self, stream: Any) -> None:
        self.stream = stream
        self.buffers = threading.local()

    def write(self, text: str) -> int:
        buffer = getattr(self.buffers, "current", None)
        if buffer is None and self.stream is None:  # no stdout at all (print then writes nothing)
            return len(text)
        return (buffer if buffer is not None else self.stream).write(text)

    def flush(self) -> None:
        if getattr(self.buffers, "current", None) is None and self.stream is not None:
            self.stream.flush()

    # what TextIOBase answers for itself (no encoding, not a terminal, no file descriptor) is the stream's
    def isatty(self) -> bool:
        return bool(self.stream is not None and self.stream.isatty())

    def fileno(self) -> int:
        if self.stream is None:
            raise io.UnsupportedOperation("fileno")
        return int(self.stream.fileno())

    def writable(self) -> bool:
        return True

    @property
    def encoding(self) -> Any:  # type: ignore[override]
        return getattr(self.stream, "encoding", None)

    @property
    def errors(self) -> Any:  # type: ignore[override]
        return getattr(self.stream, "errors", None)

    def __getattr__(self, name: str) -> Any:  # anything else: the stream's
        return getattr(self.stream, name)


_OUTPUT_LOCK = threading.Lock()
_output: list[Any] = [None, 0]  # the installed _ThreadsOwnOutput and how many calls use it


@contextmanager
def solver_messages() -> Iterator[list[str]]:
    """Keep what scikit-sundae prints during a solver call, and yield it as a list of lines (filled on exit).

    scikit-sundae 1.2.0 replaces SUNDIALS' error handler by one that prints every error to ``sys.stdout``
    (``[IDASolve, Error: -22] Root found at and very near t = ...``), a handled return included: a chattering
    compliant run printed ~2 800 such lines. The caller says a failure in its own one line, with the last of these
    when it helps. Other threads' output is not touched (``sys.stdout`` is shared: a proxy sends only the calling
    thread's writes to the buffer, and is removed when the last call using it ends).
    """
    buffer = io.StringIO()
    lines: list[str] = []
    with _OUTPUT_LOCK:
        if _output[1] == 0:
            _output[0] = _ThreadsOwnOutput(sys.stdout)
            sys.stdout = _output[0]
        _output[1] += 1
        proxy = _output[0]
    proxy.buffers.current = buffer
    try:
        yield lines
    finally:
        proxy.buffers.current = None
        with _OUTPUT_LOCK:
            _output[1] -= 1
            if _output[1] == 0:
                if sys.stdout is proxy:  # else replaced meanwhile (a test's capture): left as it is
                    sys.stdout = proxy.stream
                _output[0] = None
        lines.extend(line.strip() for line in buffer.getvalue().splitlines() if line.strip())


@intrinsic
def content_data(typingctx: Any, vector: Any) -> Any:
    """The data pointer (float64*) of a serial N_Vector or a dense SUNMatrix (column-major) given as a void pointer,
    inside a numba ``cfunc``."""
    sig = types.CPointer(types.float64)(vector)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        pointer_type = context.get_value_type(types.voidptr)
        content = builder.load(builder.bitcast(args[0], pointer_type.as_pointer()))  # N_Vector->content
        slot = builder.gep(content, [context.get_constant(types.intp, _DATA_OFFSET)])  # &content->data
        data = builder.load(builder.bitcast(slot, pointer_type.as_pointer()))
        return builder.bitcast(data, context.get_value_type(types.CPointer(types.float64)))

    return sig, codegen


@intrinsic
def as_doubles(typingctx: Any, pointer: Any) -> Any:
    """A void pointer (the user data) as float64* (inside a numba ``cfunc``)."""
    sig = types.CPointer(types.float64)(pointer)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        return builder.bitcast(args[0], context.get_value_type(types.CPointer(types.float64)))

    return sig, codegen


def _declare(library: C.CDLL, name: str, result: Any, *arguments: Any) -> Any:
    function = getattr(library, name)
    function.restype, function.argtypes = result, list(arguments)
    return function


@lru_cache(maxsize=1)
def _library() -> Any:
    """The SUNDIALS functions used here, from scikit-sundae's wheel; raises OSError/ValueError if they do not fit."""
    import sksundae

    folder = os.path.join(os.path.dirname(os.path.dirname(sksundae.__file__)), "scikit_sundae.libs")
    config = os.path.join(os.path.dirname(sksundae.__file__), "c_config.pxi")
    if not os.path.exists(config):
        raise OSError(f"{config} not found")
    with open(config, encoding="utf-8") as file:
        declared = file.read()
    if "ctypedef int sunindextype" not in declared:
        raise ValueError("scikit-sundae was not built with a 32-bit sunindextype")

    def load(name: str) -> C.CDLL:
        found = sorted(glob.glob(os.path.join(folder, f"libsundials_{name}-*.so*")))
        if not found:
            raise OSError(f"libsundials_{name} not found in {folder}")
        return C.CDLL(found[0], mode=C.RTLD_GLOBAL)

    core, vector, matrix, solver, cvode = (load(n) for n in ("core", "nvecserial", "sunmatrixdense", "sunlinsoldense", "cvode"))
    vp, d, i = C.c_void_p, C.c_double, C.c_int
    lib: dict[str, Any] = {
        "version": _declare(core, "SUNDIALSGetVersionNumber", i, C.POINTER(i), C.POINTER(i), C.POINTER(i), C.c_char_p, i),
        "context": _declare(core, "SUNContext_Create", i, i, C.POINTER(vp)),
        "context_free": _declare(core, "SUNContext_Free", i, C.POINTER(vp)),
        "quiet": _declare(core, "SUNContext_ClearErrHandlers", i, vp),
        "vector": _declare(vector, "N_VNew_Serial", vp, i, vp),
        "vector_data": _declare(vector, "N_VGetArrayPointer", C.POINTER(d), vp),
        "vector_free": _declare(vector, "N_VDestroy", None, vp),
        "matrix": _declare(matrix, "SUNDenseMatrix", vp, i, i, vp),
        "matrix_data": _declare(matrix, "SUNDenseMatrix_Data", C.POINTER(d), vp),
        "matrix_free": _declare(matrix, "SUNMatDestroy", None, vp),
        "solver": _declare(solver, "SUNLinSol_Dense", vp, vp, vp, vp),
        "solver_free": _declare(solver, "SUNLinSolFree", i, vp),
    }
    for name, result, arguments in (
        ("CVodeCreate", vp, (i, vp)), ("CVodeInit", i, (vp, vp, d, vp)), ("CVodeReInit", i, (vp, d, vp)),
        ("CVodeSStolerances", i, (vp, d, d)), ("CVodeSetUserData", i, (vp, vp)), ("CVodeSetLinearSolver", i, (vp, vp, vp)),
        ("CVodeSetJacFn", i, (vp, vp)), ("CVodeRootInit", i, (vp, i, vp)), ("CVodeSetRootDirection", i, (vp, C.POINTER(i))),
        ("CVodeSetMaxNumSteps", i, (vp, C.c_long)), ("CVodeSetMaxStep", i, (vp, d)), ("CVodeSetStopTime", i, (vp, d)),
        ("CVode", i, (vp, d, vp, C.POINTER(d), i)), ("CVodeGetRootInfo", i, (vp, C.POINTER(i))),
        ("CVodeGetNumRhsEvals", i, (vp, C.POINTER(C.c_long))), ("CVodeGetReturnFlagName", C.c_char_p, (C.c_long,)),
        ("CVodeFree", None, (C.POINTER(vp),)),
    ):
        lib[name] = _declare(cvode, name, result, *arguments)
    major, minor, patch = i(), i(), i()
    label = C.create_string_buffer(32)
    lib["version"](C.byref(major), C.byref(minor), C.byref(patch), label, 32)
    if major.value != 7:
        raise ValueError(f"scikit-sundae ships SUNDIALS {major.value}.{minor.value}, not 7")
    _check_layout(lib)
    return lib


def _check_layout(lib: dict[str, Any]) -> None:
    """The data pointers of a serial vector and of a dense matrix are where :func:`content_data` reads them."""

    def stored(handle: int) -> int | None:
        content = C.cast(handle, C.POINTER(C.c_void_p))[0]
        return C.cast(content + _DATA_OFFSET, C.POINTER(C.c_void_p))[0]

    context = C.c_void_p()
    lib["context"](0, C.byref(context))
    vector, matrix = lib["vector"](3, context), lib["matrix"](3, 3, context)
    try:
        if stored(vector) != C.cast(lib["vector_data"](vector), C.c_void_p).value:
            raise ValueError("the serial N_Vector's layout is not SUNDIALS 7's")
        if stored(matrix) != C.cast(lib["matrix_data"](matrix), C.c_void_p).value:
            raise ValueError("the dense SUNMatrix's layout is not SUNDIALS 7's")
    finally:
        lib["matrix_free"](matrix)
        lib["vector_free"](vector)
        lib["context_free"](C.byref(context))


def compiled_cvode_problem() -> str | None:
    """Why :class:`CompiledCvode` cannot run here (None: it can)."""
    try:
        _library()
    except (OSError, ValueError, AttributeError, ImportError) as error:
        return str(error)
    return None


def _release(lib: dict[str, Any], handles: dict[str, Any]) -> None:
    if handles.get("mem"):
        lib["CVodeFree"](C.byref(handles["mem"]))
    for key, free in (("solver", "solver_free"), ("matrix", "matrix_free"), ("y", "vector_free")):
        if handles.get(key):
            lib[free](handles[key])
    if handles.get("context"):
        lib["context_free"](C.byref(handles["context"]))
    handles.clear()


class CompiledCvode:
    """One CVODE solver with compiled callbacks: dense direct linear solver, scalar tolerances, root finding.

    Parameters
    ----------
    size : int
        Number of states.
    method : {'adams', 'bdf'}
        Linear multistep family.
    rtol, atol : float
        Relative and absolute tolerances [-, state units].
    rhs, jacobian, events : int
        Addresses of the numba ``cfunc`` callbacks: ``CVRhsFn``, ``CVLsJacFn`` (0: difference quotients),
        ``CVRootFn``.
    directions : sequence of int
        Crossing direction of each event function (+1 rising, -1 falling, 0 both).
    parameters : ndarray of float64
        The user data given to every callback (kept alive and writable: a mode flag may change between calls).
    max_step : float
        Largest step [s]; 0 means no limit.
    """

    def __init__(self, size: int, method: str, rtol: float, atol: float, rhs: int, jacobian: int, events: int,
                 directions: tuple[int, ...], parameters: NDArray[np.float64], max_step: float = 0.0) -> None:
        lib = self._lib = _library()
        self._handles: dict[str, Any] = {"context": C.c_void_p()}
        self._finalizer = weakref.finalize(self, _release, lib, self._handles)
        h = self._handles
        lib["context"](0, C.byref(h["context"]))
        lib["quiet"](h["context"])  # errors come back as flags, raised here with their names
        h["y"] = lib["vector"](size, h["context"])
        self.state = np.ctypeslib.as_array(lib["vector_data"](h["y"]), (size,))
        self.state[:] = 0.0
        h["mem"] = C.c_void_p(lib["CVodeCreate"](_ADAMS if method == "adams" else _BDF, h["context"]))
        self._parameters = parameters
        self._roots = (C.c_int * len(directions))()
        self._time, self._count = C.c_double(), C.c_long()
        mem = h["mem"]
        self._check(lib["CVodeInit"](mem, rhs, 0.0, h["y"]), "CVodeInit")
        self._check(lib["CVodeSStolerances"](mem, rtol, atol), "CVodeSStolerances")
        h["matrix"] = lib["matrix"](size, size, h["context"])
        h["solver"] = lib["solver"](h["y"], h["matrix"], h["context"])
        self._check(lib["CVodeSetLinearSolver"](mem, h["solver"], h["matrix"]), "CVodeSetLinearSolver")
        if jacobian:
            self._check(lib["CVodeSetJacFn"](mem, jacobian), "CVodeSetJacFn")
        self._check(lib["CVodeSetUserData"](mem, parameters.ctypes.data), "CVodeSetUserData")
        self._check(lib["CVodeRootInit"](mem, len(directions), events), "CVodeRootInit")
        self._check(lib["CVodeSetRootDirection"](mem, (C.c_int * len(directions))(*directions)), "CVodeSetRootDirection")
        self._check(lib["CVodeSetMaxNumSteps"](mem, 1_000_000), "CVodeSetMaxNumSteps")
        if max_step > 0.0:
            self._check(lib["CVodeSetMaxStep"](mem, max_step), "CVodeSetMaxStep")
        self._set_stop, self._cvode, self._mem = lib["CVodeSetStopTime"], lib["CVode"], mem
        # made once: the arguments of the calls at every event (ctypes builds them at a cost otherwise)
        self._time_ref, self._count_ref, self._vector = C.byref(self._time), C.byref(self._count), h["y"]
        self._get_rhs, self._reinit, self._root_info = lib["CVodeGetNumRhsEvals"], lib["CVodeReInit"], lib["CVodeGetRootInfo"]
        self.rhs_evaluations = 0

    def _check(self, flag: int, what: str, t: float | None = None) -> int:
        if flag < 0:
            name = self._lib["CVodeGetReturnFlagName"](flag).decode()
            raise RuntimeError(f"CVODE failed{'' if t is None else f' at t = {t!r} s'}: {what} returned {name}")
        return flag

    def _count_rhs(self) -> None:
        self._get_rhs(self._mem, self._count_ref)
        self.rhs_evaluations += self._count.value

    def restart(self, t: float, y: NDArray[np.float64]) -> None:
        """Start again from (t, y): a new history, order 1 (CVODE's counters restart too: counted first)."""
        self._count_rhs()
        self.state[:] = y
        flag = self._reinit(self._mem, t, self._vector)
        if flag < 0:
            self._check(flag, "CVodeReInit", t)

    def advance(self, t_stop: float, t_out: float | None = None) -> tuple[int, float]:
        """Integrate to ``t_stop`` or the first root: (flag, time); the state is in :attr:`state`. With ``t_out``
        (< ``t_stop``), return there instead if no root comes first: CVODE steps on as it would towards ``t_stop``
        and interpolates the state at ``t_out`` (its steps and roots are those of a run without it)."""
        mem = self._mem
        self._set_stop(mem, t_stop)
        flag = self._cvode(mem, t_stop if t_out is None else t_out, self._vector, self._time_ref, _NORMAL)
        if flag < 0:
            self._check(flag, "CVode", self._time.value)
        return flag, self._time.value

    def roots(self) -> tuple[int, ...]:
        """Which event functions have a root at the last return (+1 rising, -1 falling, 0 none)."""
        self._root_info(self._mem, self._roots)
        return tuple(self._roots)

    def total_rhs_evaluations(self) -> int:
        """Right-hand-side evaluations over every restart (difference-quotient Jacobians not included)."""
        self._lib["CVodeGetNumRhsEvals"](self._mem, C.byref(self._count))
        return self.rhs_evaluations + self._count.value

    def close(self) -> None:
        """Free the SUNDIALS objects now (they are freed with the object otherwise)."""
        self._finalizer()


def evaluate_compiled(rhs: Any, jacobian: Any, events: Any, num_events: int, parameters: NDArray[np.float64], t: float,
                      y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Call compiled callbacks (numba ``cfunc`` objects) once, as CVODE would: (y', d y'/d y with [i, j] = d y'_i /
    d y_j, event values). For checking them against their Python twins."""
    lib = _library()
    size = y.size
    context = C.c_void_p()
    lib["context"](0, C.byref(context))
    state, rate, matrix = lib["vector"](size, context), lib["vector"](size, context), lib["matrix"](size, size, context)
    try:
        np.ctypeslib.as_array(lib["vector_data"](state), (size,))[:] = y
        user = parameters.ctypes.data
        rhs.ctypes(t, state, rate, user)
        jacobian.ctypes(t, state, rate, matrix, user, None, None, None)
        values = np.zeros(num_events)
        events.ctypes(t, state, values.ctypes.data_as(C.POINTER(C.c_double)), user)
        rates = np.ctypeslib.as_array(lib["vector_data"](rate), (size,)).copy()
        jac = np.ctypeslib.as_array(lib["matrix_data"](matrix), (size * size,)).reshape(size, size).T.copy()
        return rates, jac, values
    finally:
        lib["matrix_free"](matrix)
        lib["vector_free"](rate)
        lib["vector_free"](state)
        lib["context_free"](C.byref(context))
