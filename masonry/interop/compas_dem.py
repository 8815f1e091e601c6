"""masonry as a solver of compas_dem ``Problem``\\ s (docs/assemblies.md, "masonry as a
compas_dem solver"; the ``masonry[compas]`` extra).

compas_dem's ``Problem.solve`` picks its solver by name from a fixed list, so masonry
is called beside it::

    from masonry.interop.compas_dem import solve
    results = solve(problem)            # in place of problem.solve()

:func:`solve` hands the Problem and its model to :func:`masonry.read` as one file (the
Problem saved with its model, :mod:`masonry.scenes.compas_problem`), solves the rigid
block equilibrium under self weight and returns compas_dem's ``Results`` with the edge
attributes its LMGC90 solver writes: per contact point ``contact_points``,
``force_normal`` (compression positive), ``force_tangent1`` and ``force_tangent2`` (along
the contact frame's x and y axes), and per edge ``resultant_global`` (the force on the
edge's first node, as LMGC90's ``force``), ``resultant_local``, ``force_magnitude``,
``contact_polygon``, ``contact_frame``, ``face_contact`` and ``contact_data`` (a
``FrictionContact`` with CRA's ``c_np``, ``c_nn``, ``c_u``, ``c_v``). Every block's
``transformation`` is the identity (rigid blocks at rest). ``metadata`` holds the
``verdict``, ``mu``, ``weight_N`` and, for a Problem with point loads, their collapse
``load_factor``.
"""

import json
import tempfile
from pathlib import Path

import compas
import numpy as np
from compas.geometry import Frame, Polygon, Transformation
from compas_dem.interactions import FrictionContact
from compas_dem.problem import Results

from masonry.api import read
from masonry.scenes.compas_problem import PROBLEM_DTYPE


def solve(problem, **inputs):
    """compas_dem ``Results`` of masonry's rigid block equilibrium of ``problem``.

    Parameters
    ----------
    problem : compas_dem.problem.Problem
        With its model loaded (``problem.model``).
    **inputs
        masonry's analysis inputs (``mu``, ``friction`` ...), over the Problem's.

    Returns
    -------
    compas_dem.problem.Results
        Edges keyed by the model's graph nodes (module docstring).

    Raises
    ------
    masonry.errors.MasonryError
        What masonry cannot state of the Problem (a prescribed displacement, a body
        force ...) or a bad input, in one line.
    """
    model = problem.model
    document = {"dtype": PROBLEM_DTYPE, "data": {
        "name": problem.name, "model": _plain(model),
        "boundary_conditions": _plain(problem.boundary_conditions),
        "contact_properties": _plain(problem.contact_properties)}}
    nodes = [int(key) for key in document["data"]["model"]["data"]["graph"]["node"]]
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "problem.json"
        path.write_text(json.dumps(document))
        structure = read(path, **inputs)
        result = structure.solve()
        collapse = structure.collapse() if structure.params.load is not None else None
    results = Results(model_id=str(model.guid), problem_id=str(problem.guid))
    for node in nodes:
        results.set_node(node, "transformation", Transformation())
    if result.x is not None:
        _edges(results, structure.interfaces, np.reshape(result.x, (-1, 4)), nodes)
    results.metadata.update({
        "solver": "masonry", "verdict": result.verdict, "mu": structure.params.analysis.mu,
        "weight_N": result.to_dict().get("weight_N"),
        "load_factor": None if collapse is None else collapse.load_factor})
    return results


def _plain(obj):
    """A compas object as plain JSON data."""
    return json.loads(compas.json_dumps(obj))


def _edges(results, interfaces, forces, nodes):
    """Per pair of blocks, its interfaces' points and forces (several interfaces of one
    pair are listed one after another)."""
    pairs = {}
    for k in range(len(interfaces)):
        a, b = (int(i) for i in interfaces.pair[k])
        pairs.setdefault((nodes[a], nodes[b]), []).append(k)
    for edge, ks in pairs.items():
        rows = np.concatenate([forces[interfaces.offsets[k]:interfaces.offsets[k + 1]]
                               for k in ks])
        points = np.concatenate([interfaces.polygon(k) for k in ks])
        k = ks[0]
        normal = rows[:, 0] - rows[:, 1]
        on_second = sum(
            (forces[interfaces.offsets[j]:interfaces.offsets[j + 1]] @ np.stack(
                [interfaces.normal[j], -interfaces.normal[j], interfaces.t1[j],
                 interfaces.t2[j]])).sum(axis=0) for j in ks)
        frame = Frame(interfaces.centre[k], interfaces.t1[k], interfaces.t2[k])
        contact = FrictionContact(points=[list(p) for p in interfaces.polygon(k)],
                                  frame=frame)
        contact.forces = [dict(zip(("c_np", "c_nn", "c_u", "c_v"), map(float, row)))
                          for row in rows]
        values = {
            "face_contact": True, "edge_contact": False, "point_contact": False,
            "contact_points": points.tolist(), "force_normal": normal.tolist(),
            "force_tangent1": rows[:, 2].tolist(), "force_tangent2": rows[:, 3].tolist(),
            "resultant_global": (-on_second).tolist(),
            "resultant_local": [float(rows[:, 2].sum()), float(rows[:, 3].sum()),
                                float(normal.sum())],
            "force_magnitude": float(np.linalg.norm(on_second)),
            "contact_polygon": Polygon(interfaces.polygon(k).tolist()),
            "contact_frame": frame, "contact_data": contact}
        for name, value in values.items():
            results.set_edge(edge, name, value)
