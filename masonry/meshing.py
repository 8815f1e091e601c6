"""Small triangle-mesh operations shared by the importer and the printable body."""

import numpy as np


def merge_vertices(triangles, pairs, count):
    """Merge the vertices joined by ``pairs`` and drop the triangles that collapse.

    Parameters
    ----------
    triangles : (T, 3) int
    pairs : (P, 2) int
        Vertex pairs to merge; clusters of pairs merge into their smallest index.
    count : int
        Number of vertices.

    Returns
    -------
    triangles : (T', 3) int
        The triangles renumbered to each cluster's smallest index, without the ones that
        lost a corner.
    keep : (T,) bool
        Which of the given triangles remain.
    """
    from scipy.sparse import coo_array  # scipy loads with the first mesh merged
    from scipy.sparse.csgraph import connected_components

    graph = coo_array((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, count)
    np.minimum.at(first, label, np.arange(count))
    triangles = first[label][triangles]
    keep = ((triangles[:, 0] != triangles[:, 1]) & (triangles[:, 1] != triangles[:, 2])
            & (triangles[:, 2] != triangles[:, 0]))
    return triangles[keep], keep
