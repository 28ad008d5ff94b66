"""Exception hierarchy.

Every error a user can cause derives from :class:`PidcoreError`; the CLI prints its message as
one line and exits non-zero. Messages name the file, channel or parameter and what was expected.
"""


class PidcoreError(Exception):
    """Base class of all errors caused by user input or user data."""


class InputFileError(PidcoreError):
    """A file cannot be read, or holds nothing usable (wrong dataset type, corrupt bytes)."""


class ChannelError(PidcoreError):
    """A channel is missing, ambiguous, non-finite, clipped or inconsistent with the others."""


class SignalError(PidcoreError):
    """A record cannot be analysed: too few periods, no dominant drive frequency, ..."""


class ParameterError(PidcoreError, ValueError):
    """A parameter is out of range or of the wrong kind."""


class SettingsTableError(ParameterError):
    """A settings table (a sidecar ``loadcases.csv``) has an unknown column or a bad value. The
    message names the table's own columns (``baseline_loss_factor``), which the CLI must not
    translate to its options (``--baseline-loss-factor``)."""


class StoreError(PidcoreError):
    """The HDF5 store is missing, corrupt, locked or lacks the requested entry."""


class SimulationError(PidcoreError):
    """A DEM run became unphysical (excess overlap, particle escaped) or was refused."""


def as_given(value: float) -> str:
    """A number in an error message, as the user gave it: ``:g`` where that reads back to the
    same value (``5``, ``0.05``), else the shortest text that does (``1.0000001``).

    ``:g`` alone keeps 6 digits: ``baseline_loss_factor = 1.0000001`` was refused as
    ``1: expected a fraction``, a message about a value that is accepted.
    """
    short = f"{value:g}"
    try:
        return short if float(short) == value else repr(float(value))
    except (TypeError, ValueError):  # not a number: as Python shows it
        return repr(value)
