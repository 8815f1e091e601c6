"""The printable body as 3MF in millimetres at a chosen print size (``dome.3mf``).

3MF states its unit in the file (``unit="millimeter"``), holds one object, and slicers
(PrusaSlicer, Cura, Bambu Studio) place it on the bed at that size, so no scale is
entered by hand. Written by trimesh (which needs lxml and networkx).
"""

import io

import numpy as np


def print_scale(mesh, size_mm: float) -> float:
    """Millimetres per model metre so that the largest extent of ``mesh`` (metres) is
    ``size_mm``."""
    largest = float(np.ptp(np.asarray(mesh.vertices), axis=0).max())
    if not largest > 0:
        raise ValueError("the printable body has no extent")
    return size_mm / largest


def threemf_bytes(mesh, size_mm: float, name="dome") -> bytes:
    """3MF bytes of a ``trimesh.Trimesh`` (metres) scaled so that its largest extent is
    ``size_mm`` millimetres, standing on z = 0, as one object ``name``.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        The printable body, metres.
    size_mm : float
        The largest dimension of the print, mm.
    """
    import trimesh
    from trimesh.exchange.threemf import export_3MF

    scale = print_scale(mesh, size_mm)
    vertices = np.asarray(mesh.vertices, dtype=float) * scale
    vertices[:, 2] -= vertices[:, 2].min()
    body = trimesh.Trimesh(vertices, np.asarray(mesh.faces), process=False)
    body.units = "millimeters"
    scene = trimesh.Scene()
    scene.add_geometry(body, geom_name=name, node_name=name)
    return export_3MF(scene)


def readback_3mf(data: bytes) -> dict:
    """Load 3MF bytes as a slicer would (trimesh) and report what it holds.

    Returns
    -------
    dict
        ``unit`` (the file's, e.g. ``millimeter``), ``objects``, ``extents_mm`` (3,),
        ``watertight``, ``volume_mm3``.
    """
    import trimesh

    scene = trimesh.load(io.BytesIO(data), file_type="3mf")
    body = scene.to_geometry() if isinstance(scene, trimesh.Scene) else scene
    return {"unit": scene.units, "objects": len(getattr(scene, "geometry", {None: 0})),
            "extents_mm": np.ptp(body.vertices, axis=0).tolist(),
            "watertight": bool(body.is_watertight), "volume_mm3": float(body.volume)}
