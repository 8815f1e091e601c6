"""Contact interfaces between blocks (SPEC 5, thesis 3.2.4).

One generic detector for every scene; nothing here knows about domes.

An interface is a planar polygon through which two blocks push on each other. It lies in
the plane of the *main* face (the lower block's face for bed joints), with that face's
outward normal ``n`` (pointing from the main block ``pair[:, 0]`` into the other block
``pair[:, 1]``) and in-plane basis ``t1, t2``.
"""

from dataclasses import dataclass

import numpy as np

INTERFACE_KINDS = ("horizontal", "vertical", "support", "boundary")
"""Names of the ``kind`` codes. ``support``: one block is a fixed support (the ground);
``boundary``: contact with a neighbouring web (dome boundary modes)."""


@dataclass(frozen=True, eq=False)
class Interfaces:
    """Interfaces as a struct of arrays.

    Parameters
    ----------
    pair : (K, 2) int
        ``(main block, other block)``; the normal points from the main block into the other.
    kind : (K,) int8
        Code into :data:`INTERFACE_KINDS`.
    vertices : (IV, 3) float, metres
        Polygon vertices of all interfaces, flat, counter-clockwise about ``normal``.
    offsets : (K + 1,) int
        Interface ``k`` is ``vertices[offsets[k]:offsets[k + 1]]`` (3 to 8 vertices).
    area : (K,) float, m^2
    centre : (K, 3) float, metres (area centroid)
    normal, t1, t2 : (K, 3) float
        Right-handed orthonormal frame ``(t1, t2, normal)``.
    """

    pair: np.ndarray
    kind: np.ndarray
    vertices: np.ndarray
    offsets: np.ndarray
    area: np.ndarray
    centre: np.ndarray
    normal: np.ndarray
    t1: np.ndarray
    t2: np.ndarray

    def __len__(self) -> int:
        return len(self.pair)

    @property
    def vertex_count(self) -> np.ndarray:
        """(K,) int: vertices per interface."""
        return np.diff(self.offsets)

    @property
    def vertex_interface(self) -> np.ndarray:
        """(IV,) int: the interface each vertex belongs to."""
        return np.repeat(np.arange(len(self)), self.vertex_count)

    def polygon(self, k: int) -> np.ndarray:
        return self.vertices[self.offsets[k]:self.offsets[k + 1]]

    def counts(self) -> dict:
        """Number of interfaces per kind name."""
        return {name: int((self.kind == i).sum()) for i, name in enumerate(INTERFACE_KINDS)}

    @classmethod
    def empty(cls) -> "Interfaces":
        z3 = np.zeros((0, 3))
        return cls(np.zeros((0, 2), int), np.zeros(0, np.int8), z3, np.zeros(1, int),
                   np.zeros(0), z3, z3, z3, z3)
