"""The arithmetic the golden files are blessed and compared in: numpy's and OpenBLAS's SIMD paths pinned to AVX2.

numpy dispatches float64 ``exp``, ``log``, ``sin`` ... to AVX-512 kernels where the CPU has them, and OpenBLAS picks
its matrix kernels by CPU, so the same code gives other last bits on another x86-64 machine, and an adaptive
integrator then takes other steps: the blessed files of commit 55b702f (an AVX-512 machine) differed from those of an
AVX2 machine (X86_V3) in every one of the 25 scenes. Pinned to AVX2, which every x86-64 machine of ours has, a golden
run compares the code, not the machine. The pins must be in the environment before numpy is imported: ``.ci/run``
and :mod:`tests.golden.bless` set them, and the golden suite refuses to compare without them.

This module imports nothing that loads numpy.
"""

from __future__ import annotations

import os

__all__ = ["PINS", "pinned", "unpinned_message"]

#: Environment of a golden run: OpenBLAS's Haswell (AVX2) kernels, numpy's dispatch without its AVX-512 targets.
PINS = {"OPENBLAS_CORETYPE": "Haswell", "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR"}


def pinned() -> bool:
    """Whether this process runs with :data:`PINS` (set before it started)."""
    return all(os.environ.get(key) == value for key, value in PINS.items())


def unpinned_message() -> str:
    """How to run the golden suite pinned."""
    return "the golden suite compares in pinned arithmetic: run it as " + " ".join(f"{k}='{v}'" for k, v in PINS.items()) + " python -m pytest -m golden (as .ci/run does)"
