"""The resultant of every interface's vertex forces: normal force, shear vector, point of
application and its eccentricity (the thrust line's points, Heyman's hinges).

The RBE solves for forces at the interface polygon's vertices (thesis eq. 3.23). Their
sums (:func:`masonry.rbe.result.interface_forces`) say how much is transmitted but not
where. Here the vertex forces of interface ``k`` (frame ``t1, t2, n``, centre ``C``: the
polygon's area centroid) are reduced to

- the net normal force ``sigma = sum (c - t)`` (positive in compression) along ``n``,
- the shear ``V = sum (f1 t1 + f2 t2)``, a vector in the plane,
- the point ``P = C + n x M / sigma`` in the plane, where ``M = sum (p_i - C) x F_i``:
  the resultant ``F = sigma n + V`` placed at ``P`` has the vertex forces' moment about
  the in-plane axes,
- the torsion ``T``: what is left of the moment about ``n`` at ``P``, so that
  ``(P - C) x F + T n = M`` exactly,
- the eccentricity ``e = |P - C| / s``, with ``s`` the distance from ``C`` to the
  polygon's boundary in the direction of ``P``: 0 at the centroid, 1 on the edge (a
  hinge), above 1 outside the polygon (only possible with tension).

Forces are those on the interface's other block ``pair[:, 1]`` (docs/model.md 6.1); the main block
receives their opposite.
"""

import numpy as np

NO_NORMAL_FORCE_REL = 1e-12
"""An interface whose net normal force is at most this fraction of the sum of its vertex
compressions and tensions has no point of application (NaN): its moment is a couple."""


def interface_resultants(interfaces, layout, x) -> dict:
    """Reduce every interface's vertex forces to one resultant (see the module notes).

    Parameters
    ----------
    interfaces : masonry.interfaces.Interfaces
        ``K`` interfaces with ``IV`` polygon vertices.
    layout : masonry.rbe.equilibrium.VariableLayout
        Of the same interfaces.
    x : (4 IV,) float, N
        Vertex forces ``(c, t, f1, f2)`` in the layout's order.

    Returns
    -------
    dict
        ``sigma`` (K,) float, N: net normal force, compression positive (``-normal`` of
        :func:`~masonry.rbe.result.interface_forces`); ``shear`` (K, 3) float, N;
        ``moment`` (K, 3) float, N m: the vertex forces' moment about the centre;
        ``point`` (K, 3) float, m: point of application (NaN without normal force);
        ``torsion`` (K,) float, N m (the moment about ``n`` at ``point``, or at the centre
        without one); ``eccentricity`` (K,) float (NaN without normal
        force).
    """
    c, t, f1, f2 = (layout.component(x, name) for name in layout.COMPONENTS)
    owner = layout.vertex_interface
    n, t1, t2 = interfaces.normal, interfaces.t1, interfaces.t2
    vertex_force = ((c - t)[:, None] * n[owner] + f1[:, None] * t1[owner]
                    + f2[:, None] * t2[owner])
    arm = interfaces.vertices - interfaces.centre[owner]
    count = len(interfaces)

    def per_interface(values):
        return np.stack([layout.interface_sum(v) for v in np.atleast_2d(values.T)], axis=-1)

    sigma = layout.interface_sum(c - t)
    shear = per_interface(f1[:, None] * t1[owner] + f2[:, None] * t2[owner])
    moment = per_interface(np.cross(arm, vertex_force))
    magnitude = layout.interface_sum(c + t)
    has_point = np.abs(sigma) > NO_NORMAL_FORCE_REL * magnitude
    offset = np.full((count, 3), np.nan)
    offset[has_point] = np.cross(n[has_point], moment[has_point]) / sigma[has_point, None]
    force = sigma[:, None] * n + shear
    # without a point (no normal force) the whole moment about n is torsion
    torsion = np.einsum("ij,ij->i", moment - np.cross(np.nan_to_num(offset), force), n)
    return {"sigma": sigma, "shear": shear, "moment": moment,
            "point": interfaces.centre + offset, "torsion": torsion,
            "eccentricity": eccentricity(interfaces, offset)}


def eccentricity(interfaces, offset) -> np.ndarray:
    """How far each point lies from its interface's centre, relative to the polygon.

    Parameters
    ----------
    interfaces : masonry.interfaces.Interfaces
        Convex polygons, counter-clockwise about ``normal``.
    offset : (K, 3) float, metres
        Points relative to ``interfaces.centre``, in the interface planes (any normal
        component is ignored); NaN rows stay NaN.

    Returns
    -------
    (K,) float
        ``|offset| / s``, ``s`` the distance from the centre to the boundary along
        ``offset``: 0 at the centre, 1 on the boundary.
    """
    if len(interfaces) == 0:
        return np.zeros(0)
    owner = interfaces.vertex_interface
    n = interfaces.normal
    offset = offset - np.einsum("ij,ij->i", offset, n)[:, None] * n
    length = np.linalg.norm(offset, axis=1)
    direction = offset / np.where(length > 0, length, 1.0)[:, None]
    # every edge's outward normal (edge x n for a counter-clockwise polygon) and the
    # distance of its line from the centre
    following = np.arange(len(owner)) + 1
    last = interfaces.offsets[1:] - 1
    following[last] = interfaces.offsets[:-1]
    edge = interfaces.vertices[following] - interfaces.vertices
    outward = np.cross(edge, n[owner])
    outward /= np.linalg.norm(outward, axis=1)[:, None]
    distance = np.einsum("ij,ij->i", interfaces.vertices - interfaces.centre[owner], outward)
    towards = np.einsum("ij,ij->i", direction[owner], outward)
    with np.errstate(divide="ignore", invalid="ignore"):
        exit_distance = np.where(towards > 0, distance / towards, np.inf)
    reach = np.minimum.reduceat(exit_distance, interfaces.offsets[:-1])
    return np.where(length > 0, length / reach, np.where(np.isnan(length), np.nan, 0.0))
