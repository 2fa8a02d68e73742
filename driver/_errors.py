"""The one exception base of the driver, and the error of a Fortran kernel that refused its call.

Every exception the driver raises on purpose derives from :class:`DriverError` (public as
``driver.DriverError``), and each is also the built-in it always was -- ``DeckError`` a
``ValueError``, ``NameTooLong`` an ``OSError``, ``MissingExtra`` an ``ImportError`` -- so
``except ValueError`` keeps working and ``except driver.DriverError`` catches all of them:

=====================  =====================  ==========================================
exception              also a                 raised for
=====================  =====================  ==========================================
DeckError              ValueError             bad input: deck, line and key (exit 2)
CaseFailure            DeckError              an accepted case whose computation failed
ExprError              ValueError             an expression the deck language refuses
TableValueError        ValueError             a NaN or infinity bound for a table
PublishedError         ValueError             a published record missing or malformed
FitError               ValueError             a fit the data do not determine
MissingExtra           ImportError            an optional dependency not installed
NameTooLong            OSError                an output name longer than a file name may be
LinkRefused            PermissionError        a symbolic link where the tool keeps files
SweepBusy              OSError                another run writing the same sweep record
KernelError            RuntimeError           a Fortran kernel that refused its call
=====================  =====================  ==========================================

A Ctrl-C or SIGTERM (``driver._cli.Terminated``, a ``KeyboardInterrupt``) is no error and stays
outside: every ``except Exception`` lets it pass.  Each class pickles with its fields (a worker
process's error reaches the driver whole).  This module imports nothing of the driver.
"""
from __future__ import annotations

__all__ = ["DriverError", "KernelError"]


class DriverError(Exception):
    """Base of every exception the driver raises on purpose (``except driver.DriverError``).

    Each subclass is also the built-in exception it names (``DeckError`` is a ``ValueError``,
    ``NameTooLong`` an ``OSError``), so code that catches the built-in keeps working.
    """


class KernelError(DriverError, RuntimeError):
    """A Fortran kernel refused its call (a status word meaning bad arguments) or returned a status
    that its table does not name (:func:`driver._fortran.kernel_status`).

    Parameters
    ----------
    routine : str
        The kernel routine, ``'<fortran module>.<routine>'``.
    code : int
        The status word the kernel returned.
    message : str
        What the code means (the kernel's status table).
    """

    def __init__(self, routine: str, code: int, message: str):
        self.routine, self.code, self.message = routine, int(code), message
        super().__init__(f"{routine}: status {self.code}: {message}")

    def __reduce__(self) -> tuple[type[KernelError], tuple[str, int, str]]:
        """Pickle by the three fields."""
        return (type(self), (self.routine, self.code, self.message))


# tracebacks and pickles name the public class
DriverError.__module__ = "driver"
