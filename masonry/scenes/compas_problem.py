"""A compas_dem ``Problem`` read as blocks and analysis inputs (docs/assemblies.md,
"compas_dem Problem").

A Problem saved with its model (``data.model``, a ``BlockModel``: the blocks) states:

- ``contact_properties.data.contact_model``: a ``MohrCoulomb`` law, its ``mu`` (or
  ``phi``, degrees), cohesion ``c`` and tensile cut-off ``t_c`` (pascals: compas_dem is
  SI) -> masonry's ``mu``, ``cohesion_kpa`` and ``tensile_kpa``; another law is refused;
  ``joint_model`` (stiffnesses) means nothing to rigid blocks and is not read;
- ``boundary_conditions`` (one object, or a list of groups): ``g`` with the materials'
  ``density`` -> the self weight (masonry's ``density`` times ``g / 9.81``: the same
  weight); every block carries it, as compas_dem's solvers apply it (its ``gravity`` flag
  is not read); ``point_loads`` -> loads for a collapse factor
  (:func:`masonry.rbe.loads.point_load_spec` says which it can state); zero prescribed
  displacements of all six components -> supports, any other refused by block;
  ``body_forces`` and ``surface_loads`` refused.

compas_dem 0.6 saves a Problem without its model (``model_id`` only): refused, with what
to do instead.
"""

import math
from dataclasses import dataclass, field
from numbers import Real

from masonry.scenes.soup import AssemblyError
from masonry.tolerances import G

PROBLEM_DTYPE = "compas_dem.problem/Problem"
"""compas_dem's problem: a block model, boundary conditions, contact properties."""

CONTACT_MODELS = ("compas_dem.interactions/MohrCoulomb",)
"""The contact laws masonry reads."""


@dataclass(frozen=True)
class ProblemInputs:
    """What a Problem states besides its blocks (SI units).

    Attributes
    ----------
    mu, cohesion_Pa, tensile_Pa : float or None
        The contact law; None where the file states none.
    density : float or None
        kg/m^3, scaled by ``g / 9.81`` (masonry's weight is ``density 9.81 V``).
    fixed : tuple of int
        Blocks (indices in the model's node order) fixed by zero displacements.
    point_loads : tuple of dict
        ``block`` (index), ``force`` (3 N), ``point`` (3 m or None: the block's
        centroid), ``where`` (the load, as the file has it).
    """

    mu: float | None = None
    cohesion_Pa: float | None = None
    tensile_Pa: float | None = None
    density: float | None = None
    fixed: tuple = ()
    point_loads: tuple = field(default_factory=tuple)


def problem_model(document: dict, data_of) -> dict:
    """The ``BlockModel`` object a Problem holds; ``data_of`` reads a COMPAS object's
    ``data``."""
    data = data_of(document, "the problem")
    model = data.get("model")
    if model is None:
        raise AssemblyError(f"problem: no model (model_id {data.get('model_id')!r}): a "
                            "compas_dem 0.6 Problem is saved without its blocks; save it "
                            "with them (data.model) or solve it in Python with "
                            "masonry.interop.compas_dem.solve")
    return model


def problem_inputs(document: dict, data_of, nodes: list, materials: list) -> ProblemInputs:
    """The inputs of a Problem (module docstring).

    Parameters
    ----------
    document : dict
        The file's Problem object.
    data_of : callable
        ``(obj, where) -> dict``, a COMPAS object's ``data``, checked.
    nodes : list
        The model's graph node keys (str), in block order.
    materials : list
        Per block, its material's data (dict) or None.
    """
    data = data_of(document, "the problem")
    law = _contact_law(data.get("contact_properties"), data_of)
    groups = _groups(data.get("boundary_conditions"), data_of)
    index = {key: i for i, key in enumerate(nodes)}
    _refuse_loads(groups, data_of)
    g = _gravity(groups)
    density = _density(materials)
    return ProblemInputs(
        **law, density=None if density is None else density * g / G,
        fixed=_fixed(groups, index, data_of),
        point_loads=tuple(_point_loads(groups, index, data_of)))


def _number(value, where: str, low=None, allow_none=True):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value) \
            or (low is not None and value < low):
        bound = "" if low is None else f" >= {low:g}"
        raise AssemblyError(f"{where} is {value!r}, expected a finite number{bound}")
    return float(value)


def _contact_law(properties, data_of) -> dict:
    if properties is None:
        return {}
    model = data_of(properties, "contact_properties").get("contact_model")
    if model is None:
        return {}
    dtype = model.get("dtype") if isinstance(model, dict) else model
    if dtype not in CONTACT_MODELS:
        raise AssemblyError(f"contact model {dtype!r}: not supported (masonry reads "
                            f"{', '.join(CONTACT_MODELS)})")
    law = data_of(model, "contact model")
    mu = _number(law.get("mu"), "contact model: mu", low=0.0)
    if mu is None:
        phi = _number(law.get("phi"), "contact model: phi", low=0.0)
        mu = None if phi is None else math.tan(math.radians(phi))
    if mu is not None and not mu > 0:
        raise AssemblyError(f"contact model: mu is {mu!r}, expected a number > 0")
    c = _number(law.get("c"), "contact model: c (cohesion, Pa)", low=0.0)
    t_c = _number(law.get("t_c"), "contact model: t_c (tensile strength, Pa)", low=0.0)
    return {"mu": mu, "cohesion_Pa": c, "tensile_Pa": t_c}


def _groups(conditions, data_of) -> list:
    """The boundary condition groups' data (one object or a list of them)."""
    if conditions is None:
        return []
    listed = conditions if isinstance(conditions, list) else [conditions]
    return [data_of(group, f"boundary condition {i}") for i, group in enumerate(listed)]


def _entries(group: dict, key: str, g: int, data_of) -> list:
    """``(where, data)`` of the group's ``key`` entries (objects or plain dicts)."""
    entries = group.get(key) or []
    if not isinstance(entries, list):
        raise AssemblyError(f"boundary condition {g}: {key} is not a list")
    return [(f"{key[:-1].replace('_', ' ')} {i} of boundary condition {g}",
             data_of(e, f"{key} {i}") if isinstance(e, dict) and "dtype" in e else e)
            for i, e in enumerate(entries)]


def _gravity(groups) -> float:
    values = {_number(group.get("g", G), f"boundary condition {i}: g", low=0.0)
              for i, group in enumerate(groups)} or {G}
    if len(values) > 1 or None in values:
        raise AssemblyError(f"boundary conditions: g is {sorted(map(str, values))}, "
                            "expected one value")
    return values.pop()


def _density(materials) -> float | None:
    values = {_number(m.get("density"), f"material {m.get('name')!r}: density", low=0.0)
              for m in materials if m is not None}
    values.discard(None)
    if len(values) > 1:
        raise AssemblyError(f"materials: densities {sorted(values)}: masonry takes one "
                            "density for every block")
    return values.pop() if values else None


def _refuse_loads(groups, data_of):
    for g, group in enumerate(groups):
        for key in ("body_forces", "surface_loads"):
            for where, _ in _entries(group, key, g, data_of):
                raise AssemblyError(f"{where}: not supported (masonry reads self weight "
                                    "and point loads)")


def _block(entry: dict, where: str, index: dict) -> int:
    key = entry.get("block_index") if isinstance(entry, dict) else None
    if isinstance(key, bool) or str(key) not in index:
        raise AssemblyError(f"{where}: block_index {key!r} is no block of the model (it has "
                            f"{len(index)})")
    return index[str(key)]


def _fixed(groups, index: dict, data_of) -> tuple:
    """Blocks whose six displacement components are all prescribed zero; any other
    prescribed displacement is refused by block."""
    components = {}
    for g, group in enumerate(groups):
        for where, entry in _entries(group, "displacements", g, data_of):
            block = _block(entry, where, index)
            values = components.setdefault(block, [None] * 6)
            for k, name in enumerate(("translation", "rotation")):
                given = entry.get(name) or [None] * 3
                for j, v in enumerate(given):
                    if v is not None:
                        values[3 * k + j] = _number(v, f"{where}: {name}")
    for block, values in components.items():
        if any(v != 0.0 for v in values):
            stated = ", ".join("free" if v is None else f"{v:g}" for v in values)
            raise AssemblyError(f"prescribed displacement on block {list(index)[block]} "
                                f"({stated}): not supported (masonry fixes a block: all "
                                "six components 0)")
    return tuple(sorted(components))


def _point_loads(groups, index: dict, data_of):
    for g, group in enumerate(groups):
        for where, entry in _entries(group, "point_loads", g, data_of):
            block = _block(entry, where, index)
            force = entry.get("force") or [0.0, 0.0, 0.0]
            point = entry.get("point")
            if entry.get("moment") is not None:
                raise AssemblyError(f"{where} on block {list(index)[block]}: a moment is "
                                    "not supported (give the load's point instead)")
            if not isinstance(force, list) or len(force) != 3 or (
                    point is not None and (not isinstance(point, list) or len(point) != 3)):
                raise AssemblyError(f"{where}: force and point must be three numbers each")
            force = [_number(v, f"{where}: force", allow_none=False) for v in force]
            if point is not None:
                point = [_number(v, f"{where}: point", allow_none=False) for v in point]
            yield {"block": block, "force": force, "point": point,
                   "where": f"{where} on block {list(index)[block]}"}
