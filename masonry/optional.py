"""Optional modules, and interrupts that arrive as another error.

An extension module's loader can turn an interrupt into an ``ImportError``: pybind11
(rhino3dm, pymetis, highspy) raises ``ImportError("initialization failed")`` from the
``KeyboardInterrupt`` that Ctrl-C (or the command's SIGTERM handler) raised while the
module initialised. Caught as "not installed", that interrupt would be lost and the run
would go on without the module. :func:`optional_import` raises the interrupt instead,
and :func:`raise_interrupt` does the same for any error caught as data (a sweep's
failed variant).
"""

import importlib


def interrupt_of(error: BaseException) -> BaseException | None:
    """The interrupt (a ``BaseException`` that is not an ``Exception``: Ctrl-C, the
    command's SIGTERM, ``SystemExit``) among ``error``'s causes and contexts, or None."""
    seen = set()
    while error is not None and id(error) not in seen:
        if not isinstance(error, Exception):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return None


def raise_interrupt(error: BaseException) -> None:
    """Raise the interrupt behind ``error`` (:func:`interrupt_of`), if there is one."""
    interrupt = interrupt_of(error)
    if interrupt is not None:
        raise interrupt


def optional_import(name: str):
    """The module ``name``, or None when it is not installed (or does not load); an
    interrupt during its import is raised, even when its loader made it an
    ``ImportError``."""
    try:
        return importlib.import_module(name)
    except ImportError as error:
        raise_interrupt(error)
        return None
