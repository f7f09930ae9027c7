"""Freed memory kept in the process for the next training step (glibc ``malloc``), not handed back to the OS.

torch allocates every activation and gradient of a training step afresh; glibc serves large blocks with fresh
pages from the OS and returns them when freed, so every step pays the kernel's zeroing of each page on first touch
(BGFN's [T, B, N, D] tensors are megabytes each). Raising glibc's ``mmap`` and trim thresholds keeps freed blocks in
the heap, already mapped for the next step, as a caching allocator (jemalloc, tcmalloc) does by default. It changes
no number, only where a tensor's memory comes from; a training process keeps the memory of its largest step until
it exits. Elsewhere than glibc (macOS, musl) nothing happens.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

#: ``mallopt`` parameters of glibc's ``<malloc.h>``.
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: Blocks up to this size come from the heap (above it from ``mmap``), bytes: larger than any tensor of a step.
MMAP_THRESHOLD_BYTES = 1 << 30
#: Free memory at the top of the heap kept instead of trimmed, bytes (the largest value the C ``int`` holds).
TRIM_THRESHOLD_BYTES = (1 << 31) - 1


def keep_freed_memory() -> bool:
    """Set glibc's ``mmap`` and trim thresholds for this process (module docstring); True where it took effect.

    Idempotent; the training loop and ``make bench``'s training steps call it, so both measure the same thing.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").mallopt
    except (OSError, AttributeError):             # no C library found, or one without mallopt (musl)
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)) and bool(mallopt(M_TRIM_THRESHOLD,
                                                                                 TRIM_THRESHOLD_BYTES))
