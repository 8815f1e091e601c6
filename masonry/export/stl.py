"""The printable body as binary STL and OBJ, and the read-back check a slicer would make
(docs/model.md 7: ``dome.stl``, ``dome.obj``).

Binary STL stores float32 coordinates and no connectivity: a loader rebuilds the mesh by
merging equal vertices. :func:`readback_check` loads the bytes the same way (trimesh,
merging vertices) and checks what the written file really holds, which is what a slicer
will see. Coordinates are metres; slicers read STL in millimetres, so scale on import.
"""

import io

import numpy as np

from masonry.export.obj import UP_AXIS
from masonry.printable import PrintableError
from masonry.tolerances import READBACK_VOLUME_RTOL


STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)),
                       ("attributes", "<u2")])
"""One facet of a binary STL (after the 80-byte header and the uint32 facet count)."""

NORMAL_AGREEMENT = 1 - 1e-6
"""Least cosine between a stored normal and the normal of its float32 vertices: float32
rounding of the stored unit vector alone moves it by about 1e-7."""


def float32_normals(triangles32, fallback) -> np.ndarray:
    """Unit normals of the triangles as stored: from their float32 vertices, by the
    right-hand rule of their winding, computed in float64.

    Parameters
    ----------
    triangles32 : (F, 3, 3) float32
    fallback : (F, 3) float
        Used where the float32 triangle has no area (its vertices rounded onto a line).

    Notes
    -----
    trimesh's ``export_stl`` stores the normals of the float64 mesh and writes zeros for
    triangles too thin for its threshold: on the sliver facets of a dome's union these
    disagree with the float32 vertices the file holds, and admesh and slicers "fix" them.
    """
    t = np.asarray(triangles32, dtype=np.float64)
    cross = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    length = np.linalg.norm(cross, axis=1)
    return np.where(length[:, None] > 0, cross / np.where(length > 0, length, 1.0)[:, None],
                    fallback)


def stl_bytes(mesh, scale=1.0) -> bytes:
    """Binary STL of a ``trimesh.Trimesh``: float32 coordinates (metres times ``scale``)
    and, per facet, the unit normal of those float32 vertices (:func:`float32_normals`)."""
    triangles = (np.asarray(mesh.vertices)[mesh.faces] * scale).astype(np.float32)
    packed = np.zeros(len(triangles), dtype=STL_RECORD)
    packed["vertices"] = triangles
    packed["normal"] = float32_normals(triangles, mesh.face_normals)
    header = b"masonry printable body".ljust(80, b" ")
    return header + np.uint32(len(packed)).tobytes() + packed.tobytes()


def stored_normal_errors(stl: bytes) -> int:
    """How many facets of binary STL bytes store a normal that is not the unit normal
    of their float32 vertices' winding (within :data:`NORMAL_AGREEMENT`)."""
    count = int(np.frombuffer(stl, dtype="<u4", count=1, offset=80)[0])
    packed = np.frombuffer(stl, dtype=STL_RECORD, count=count, offset=84)
    normal = packed["normal"].astype(np.float64)
    expected = float32_normals(packed["vertices"], np.zeros((count, 3)))
    agree = np.einsum("ij,ij->i", normal, expected) >= NORMAL_AGREEMENT
    unit = np.abs(np.linalg.norm(normal, axis=1) - 1) <= 1e-6
    return int((~(agree & unit)).sum())


def obj_body_bytes(mesh, name="dome") -> bytes:
    """Wavefront OBJ of a ``trimesh.Trimesh`` as one object ``name``: vertices with
    8 decimals (metres, 1e-8 m, far below the body's cleaning distance), triangles,
    no normals."""
    from trimesh.exchange.obj import export_obj

    text = export_obj(mesh, include_normals=False, include_color=False,
                      include_texture=False, header=None)
    return (f"# masonry printable body, metres, {UP_AXIS}\no {name}\n" + text).encode()


def readback_check(stl: bytes, volume_m3=None, rtol=READBACK_VOLUME_RTOL) -> dict:
    """Load STL bytes as a slicer would (trimesh, vertices merged) and check the body.

    Parameters
    ----------
    stl : bytes
        Binary STL.
    volume_m3 : float, optional
        Expected volume (the union's, from :func:`masonry.printable.printable_body`).
    rtol : float
        Accepted relative difference from ``volume_m3``.

    Returns
    -------
    dict
        ``watertight``, ``winding_consistent`` (bool), ``bodies``, ``triangles``,
        ``vertices``, ``degenerate_faces`` (zero area after the float32 round trip and
        the merge), ``normal_errors`` (stored normals that are not the unit normal of
        their facet's float32 vertices, :func:`stored_normal_errors`), ``volume_m3``
        (float, positive when the normals point outward), ``bytes`` (size of the file).

    Raises
    ------
    PrintableError
        When the loaded mesh is not watertight, not consistently wound, not one body,
        has degenerate faces, or its volume is not positive or differs from ``volume_m3``
        by more than ``rtol``. The error's ``report`` holds the dict.
    """
    import trimesh

    mesh = trimesh.load_mesh(io.BytesIO(stl), file_type="stl", process=True)
    report = {
        "watertight": bool(mesh.is_watertight),
        "winding_consistent": bool(mesh.is_winding_consistent),
        "bodies": int(mesh.body_count),
        "triangles": len(mesh.faces),
        "vertices": len(mesh.vertices),
        "degenerate_faces": int((mesh.area_faces <= 0).sum()),
        "normal_errors": stored_normal_errors(stl),
        "volume_m3": float(mesh.volume),
        "bytes": len(stl),
    }
    problems = [text for text, failed in (
        ("not watertight", not report["watertight"]),
        ("inconsistent winding", not report["winding_consistent"]),
        (f"{report['bodies']} bodies, expected 1", report["bodies"] != 1),
        (f"{report['degenerate_faces']} degenerate faces", report["degenerate_faces"]),
        (f"{report['normal_errors']} stored normals disagree with their facets",
         report["normal_errors"]),
        ("no volume (inward normals?)", not report["volume_m3"] > 0),
        (f"volume {report['volume_m3']:.6g} m^3, expected {volume_m3} within {rtol:g}",
         volume_m3 is not None
         and not np.isclose(report["volume_m3"], volume_m3, rtol=rtol, atol=0.0)),
    ) if failed]
    if problems:
        raise PrintableError("STL read back: " + "; ".join(problems), report)
    return report
