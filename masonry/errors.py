"""The errors a user can cause, under one base class.

Every error that bad input, an unusable file or a structure that cannot be modelled
raises is a :class:`MasonryError`: a front end catches this one class, prints its message
in one line and exits (the command line with code 2), before anything is written.
Anything else is a fault of the program.
"""


class MasonryError(Exception):
    """A user-facing error: the input, a file or the structure, not the program, is at
    fault. The message says what was wrong and what is expected, in one line."""


class ParameterError(MasonryError, ValueError):
    """A parameter is out of its valid range. The message names parameter, value, range.

    ``related`` names the other parameters the check depends on (a front end names the
    ones its user gave when ``name`` itself was not given); ``where`` says where the value
    was read (a file), if not from the caller.
    """

    def __init__(self, name, value, expected, *, related=(), where=None):
        super().__init__(f"invalid parameter {name}={value!r}: expected {expected}"
                         + (f" ({where})" if where else ""))
        self.name = name
        self.value = value
        self.expected = expected
        self.related = tuple(related)
        self.where = where


class NoForcesError(MasonryError, ValueError):
    """A result asked for its forces has none: its equilibrium was not solved, or the
    friction-net program found no forces that balance the blocks (infeasible)."""
