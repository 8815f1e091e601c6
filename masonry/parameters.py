"""Declared parameters: how every stage states its inputs, once.

Each concern of a run is a frozen dataclass of declared fields: a scene kind's geometry
(:mod:`masonry.scenes`), the analysis (:mod:`masonry.rbe.settings`), the live load
(:mod:`masonry.rbe.loads`) and the outputs (:mod:`masonry.outputs`). A field is
declared with :func:`declare`: its default, what it means, its unit, the values it may
take and the tag that names it in a run's folder. Validation, the structure id, the
geometry cache's key, ``00_parameters.txt`` and the command line's options all read these
declarations (:mod:`masonry.params` composes them); nothing lists a parameter twice.
"""

import dataclasses
import math
import numbers
import os
import tomllib
from dataclasses import dataclass

from masonry.errors import ParameterError

MAX_INTEGER = 10**12
"""No count of anything here comes near it; larger integers would overflow floats."""


@dataclass(frozen=True)
class Declaration:
    """What one parameter is.

    Parameters
    ----------
    doc : str
        What it means, with its unit where it has one (``00_parameters.txt``, help).
    kind : {'float', 'int', 'str', 'bool', 'any'}
        Its type; numbers are finite, ints within :data:`MAX_INTEGER`.
    choices : tuple of str, optional
        The values a ``str`` may take.
    low, high : float, optional
        Inclusive bounds of a number.
    expected : str
        What the error says is expected when the value is refused (default: from the
        kind, choices and bounds).
    check : callable, optional
        ``check(value) -> bool``, beyond the bounds (``expected`` says what it asks).
    optional : bool
        None is a valid value (the parameter is not set).
    tag : str or None
        Its tag in the structure id (:func:`masonry.params.structure_id`); None: not in
        the id.
    head : bool
        Always in the structure id's head (a scene's dimensions), else only when it
        differs from its default.
    names_geometry : bool
        Decides the geometry and interfaces: part of the geometry cache's key.
    option : str, optional
        The command line's option when it is not ``--`` and the name with dashes
        (``--blocks`` for ``arch_blocks``).
    help : str
        The command line's help when it says more than ``doc``, the range and the
        default (of a switch, its option that turns it on).
    off_help : str
        The help of a switch's ``--no-`` option (a boolean that defaults to true, or
        an optional one).
    metavar : str, optional
        The command line's name of the value (default: the option's, upper case).
    repeat : bool
        The option may be given several times, its values collected in a list.
    """

    doc: str
    kind: str = "float"
    choices: tuple | None = None
    low: float | None = None
    high: float | None = None
    expected: str = ""
    check: object = None
    optional: bool = False
    tag: str | None = None
    head: bool = False
    names_geometry: bool = False
    option: str | None = None
    help: str = ""
    off_help: str = ""
    metavar: str | None = None
    repeat: bool = False

    def refusal(self, name, value) -> ParameterError | None:
        """The error for ``value`` of parameter ``name``, or None when it is valid."""
        if value is None:
            return None if self.optional else ParameterError(name, value, self._expected())
        if self.kind in ("float", "int"):
            integer = self.kind == "int"
            if isinstance(value, bool) or not isinstance(value, (int,) if integer
                                                         else (int, float)):
                return ParameterError(name, value, "an integer" if integer else "a number")
            if not math.isfinite(value):
                return ParameterError(name, value, "a finite number")
            if integer and abs(value) > MAX_INTEGER:
                return ParameterError(name, value, f"an integer of at most {MAX_INTEGER:.0e}")
            if ((self.low is not None and value < self.low)
                    or (self.high is not None and value > self.high)):
                return ParameterError(name, value, self._expected())
        elif self.kind == "bool" and not isinstance(value, bool):
            return ParameterError(name, value, self.expected or "true or false")
        elif self.kind == "str" and (not isinstance(value, str) or (
                self.choices is not None and value not in self.choices)):
            return ParameterError(name, value, self._expected())
        if self.check is not None and not self.check(value):
            return ParameterError(name, value, self._expected())
        return None

    def _expected(self) -> str:
        if self.expected:
            return self.expected
        if self.choices is not None:
            return f"one of {', '.join(self.choices)}"
        if self.low is not None and self.high is not None:
            return f"{self.low:g} to {self.high:g}"
        return {"int": "an integer", "str": "a name"}.get(self.kind, "a number")


def declare(default, doc, **declaration) -> dataclasses.Field:
    """A dataclass field with its :class:`Declaration` (keyword arguments) as metadata."""
    return dataclasses.field(default=default,
                             metadata={"declaration": Declaration(doc, **declaration)})


def declarations(group) -> dict:
    """Field name -> :class:`Declaration` of a declared dataclass (or one of its
    instances), in declaration order."""
    return {f.name: f.metadata["declaration"] for f in dataclasses.fields(group)
            if "declaration" in f.metadata}


def defaults(group) -> dict:
    """Field name -> default of a declared dataclass."""
    return {f.name: f.default for f in dataclasses.fields(group)
            if "declaration" in f.metadata}


def values(group) -> dict:
    """Field name -> value of a declared dataclass instance, in declaration order."""
    return {name: getattr(group, name) for name in declarations(group)}


def plain(value):
    """``value`` with a number of another library as Python's own: a numpy integer as
    an ``int``, a numpy float as a ``float`` (numbers of ``numbers.Integral`` and
    ``numbers.Real``), so that it validates and prints as one. A boolean stays one."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return value
    return int(value) if isinstance(value, numbers.Integral) else float(value)


def check_fields(group):
    """Raise the first :class:`~masonry.errors.ParameterError` of ``group``'s fields
    (type, choices, bounds, checks), in declaration order."""
    for name, declaration in declarations(group).items():
        error = declaration.refusal(name, getattr(group, name))
        if error is not None:
            raise error


def text_of(value) -> str:
    """A value in a structure id: a number as ``%g`` where that is the value to 15
    significant digits, else those 15 digits, trailing zeros dropped (``2011.8216``:
    ``%g`` would give ``2011.82``, the name of another input); anything else as text,
    without colons (``polygon:16`` -> ``polygon16``, a name every file system takes).
    Fifteen digits tell any two decimal inputs apart, and name ``0.1 + 0.2`` as ``0.3``."""
    if not isinstance(value, float):
        return str(value).replace(":", "")
    value = float(f"{value:.15g}")
    short = f"{value:g}"
    return short if float(short) == value else f"{value:.15g}"


MAX_TOML_BYTES = 2**20
"""Parameter and study files are a few hundred bytes; a larger one is not one of them."""


def read_toml(path, name) -> dict:
    """The table of a TOML file (UTF-8, a byte order mark allowed).

    Raises
    ------
    ParameterError
        Named ``name`` (the option that gave the path): the path is empty, the file is
        missing, unreadable or a folder, not UTF-8, not TOML, or nested deeper than the
        TOML reader recurses.
    """
    if str(path).strip() == "":
        raise ParameterError(name, str(path), "a TOML file (an empty path names nothing)")
    try:
        if os.path.exists(path) and not os.path.isfile(path):
            raise ParameterError(name, str(path), "a TOML file, not a folder or a device")
        if os.path.getsize(path) > MAX_TOML_BYTES:
            raise ParameterError(name, str(path), f"a TOML file of at most "
                                                  f"{MAX_TOML_BYTES // 2**20} MiB")
        with open(path, "rb") as f:
            text = f.read().decode("utf-8-sig")
        return tomllib.loads(text)
    except OSError as error:
        raise ParameterError(name, str(path), f"a readable TOML file "
                                              f"({error.strerror or error})") from None
    except UnicodeDecodeError as error:
        raise ParameterError(name, str(path), f"a UTF-8 text file (byte {error.start} is "
                                              f"not UTF-8)") from None
    except tomllib.TOMLDecodeError as error:
        raise ParameterError(name, str(path), f"a valid TOML file ({error})") from None
    except RecursionError:
        raise ParameterError(name, str(path), "a TOML file of tables and arrays nested "
                                              "a few levels deep, not thousands") from None
