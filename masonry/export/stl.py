"""The printable body as binary STL and OBJ, and the read-back check a slicer would make
(SPEC 7: ``dome.stl``, ``dome.obj``).

Binary STL stores float32 coordinates and no connectivity: a loader rebuilds the mesh by
merging equal vertices. :func:`readback_check` loads the bytes the same way (trimesh,
merging vertices) and checks what the written file really holds, which is what a slicer
will see. Coordinates are metres; slicers read STL in millimetres, so scale on import.
"""

import io

import numpy as np

from masonry.printable import PrintableError
from masonry.tolerances import READBACK_VOLUME_RTOL


def stl_bytes(mesh) -> bytes:
    """Binary STL of a ``trimesh.Trimesh`` (float32 coordinates, metres)."""
    from trimesh.exchange.stl import export_stl

    return export_stl(mesh)


def obj_body_bytes(mesh, name="dome") -> bytes:
    """Wavefront OBJ of a ``trimesh.Trimesh`` as one object ``name``: vertices with
    8 decimals (metres, 1e-8 m, far below the body's cleaning distance), triangles,
    no normals."""
    from trimesh.exchange.obj import export_obj

    text = export_obj(mesh, include_normals=False, include_color=False,
                      include_texture=False, header=None)
    return (f"# masonry printable body, metres, z up\no {name}\n" + text).encode()


def readback_check(stl: bytes, volume_m3=None, rtol=READBACK_VOLUME_RTOL) -> dict:
    """Load STL bytes as a slicer would (trimesh, vertices merged) and check the body.

    Parameters
    ----------
    stl : bytes
        Binary or ASCII STL.
    volume_m3 : float, optional
        Expected volume (the union's, from :func:`masonry.printable.printable_body`).
    rtol : float
        Accepted relative difference from ``volume_m3``.

    Returns
    -------
    dict
        ``watertight``, ``winding_consistent`` (bool), ``bodies``, ``triangles``,
        ``vertices``, ``degenerate_faces`` (zero area after the float32 round trip and
        the merge), ``volume_m3`` (float), ``bytes`` (size of the file).

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
        "volume_m3": float(mesh.volume),
        "bytes": len(stl),
    }
    problems = [text for text, failed in (
        ("not watertight", not report["watertight"]),
        ("inconsistent winding", not report["winding_consistent"]),
        (f"{report['bodies']} bodies, expected 1", report["bodies"] != 1),
        (f"{report['degenerate_faces']} degenerate faces", report["degenerate_faces"]),
        ("no volume", not report["volume_m3"] > 0),
        (f"volume {report['volume_m3']:.6g} m^3, expected {volume_m3} within {rtol:g}",
         volume_m3 is not None
         and not np.isclose(report["volume_m3"], volume_m3, rtol=rtol, atol=0.0)),
    ) if failed]
    if problems:
        raise PrintableError("STL read back: " + "; ".join(problems), report)
    return report
