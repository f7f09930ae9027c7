"""Exceptions with messages that name the file, the field and what was expected."""

from __future__ import annotations

from pathlib import Path


class DataError(ValueError):
    """Bad input data: a file, a field of it, or a parameter does not meet what the code expects.

    Parameters
    ----------
    source : str or Path
        The file (or dataset name) the bad value came from.
    field : str
        The field/column/parameter that is wrong.
    expected : str
        What was expected, in words.
    found : str, optional
        What was found instead.
    """

    def __init__(self, source: str | Path, field: str, expected: str, found: str | None = None):
        self.source = str(source)
        self.field = field
        self.expected = expected
        self.found = found
        msg = f"{self.source}: field '{field}': expected {expected}"
        if found is not None:
            msg += f", found {found}"
        super().__init__(msg)


class ChecksumError(DataError):
    """A downloaded or mirrored file does not match its pinned checksum."""
