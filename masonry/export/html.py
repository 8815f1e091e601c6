"""``dome.html``: the bricks in 3D in one self-contained page, opened offline by any
browser, to turn, zoom, colour by class, force or collapse mechanism, and pick a brick.

One plotly ``Mesh3d`` holds the bricks' outer faces (a face wholly in contact with
another brick of the scene is inside the structure and never seen): vertices as float32,
triangles as int32, which plotly writes as base64 typed arrays. A colouring is one value
per brick, expanded to the brick's vertices by the page's script when the user chooses
it. plotly.js is read from one file beside the run folders, shared by the pages of an
output root (:func:`plotly_file`; ``html_plotly = "shared"``, a page that does not find it
says where it looked), or written into the page (``inline``); no network needed.
"""

import html
import json

import numpy as np

from masonry.blocks import BLOCK_CLASSES, CLASS_COLOURS
from masonry.rbe.collapse_result import vertex_displacements
from masonry.tolerances import ADHESION_REPORTED_REL, FACE_COVERED, TENSION_REPORTED_REL

FORCE_PERCENTILE = 99.0
"""A force colouring's scale ends at this percentile of the free bricks' values (the
bricks on the ground would otherwise set it); the colour bar says so, and a picked
brick shows its value."""

VIEW = (-45.0, 28.0)
"""Degrees: the azimuth (from x) and elevation of the page's first view, towards the
structure's middle."""

FIT = 0.85
"""The first view sees the whole structure, its projection filling at most this fraction
of the plot's height and of :data:`FIT_ASPECT` times it across."""

FIT_ASPECT = 1.2
"""The width over the height of the plot (the window less the bar and the colour bar)
the first view is fitted to: a landscape window's, or less."""

SEEN_THROUGH = "#d0d0d0"
"""The bricks' colour when the page shows the joints that use adhesion
(:func:`adhesion_trace`), drawn at :data:`JOINTS_SEEN_THROUGH` opacity so the joints
inside show through them."""

JOINTS_SEEN_THROUGH = 0.15
"""The bricks' opacity when the page shows the joints that use adhesion."""

FOVY = np.pi / 4
"""Radians: plotly's 3D perspective camera's vertical field of view."""

_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ margin: 0; font: 13px sans-serif; }}
#bar {{ padding: 6px 10px; border-bottom: 1px solid #ddd; }}
#pick {{ position: absolute; top: 44px; left: 10px; z-index: 10; white-space: pre;
  background: rgba(255, 255, 255, 0.85); padding: 4px 6px; }}
#plot {{ position: absolute; top: 34px; bottom: 0; left: 0; right: 0; }}
</style></head>
<body>
<div id="bar"><b>{title}</b> &nbsp; colour by <select id="colouring"></select>
&nbsp; drag: turn, scroll: zoom, click: a brick</div>
<div id="pick"></div>
<script id="bricks" type="application/json">{bricks}</script>
<div id="plot">{plot}</div>
</body></html>
"""

_SCRIPT = """
const gd = document.getElementById('{plot_id}');
const page = JSON.parse(document.getElementById('bricks').textContent);
const owner = new Int32Array(page.first[page.first.length - 1]);
for (let b = 0; b + 1 < page.first.length; b++) {
  owner.fill(b, page.first[b], page.first[b + 1]);
}
const select = document.getElementById('colouring');
page.colourings.forEach((c, i) => {
  const option = new Option(c.empty ? c.label + ': none' : c.label, i);
  option.disabled = !!c.empty;
  select.add(option);
});
const joints = gd.data.findIndex(t => t.name === 'joints');
select.onchange = () => {
  const c = page.colourings[select.value];
  const s = c.style;
  Plotly.restyle(gd, {intensity: [Float32Array.from(owner, b => c.values[b])],
    colorscale: [s.colorscale], cmin: s.cmin, cmax: s.cmax, colorbar: [s.colorbar],
    showscale: !c.joints, opacity: c.opacity === undefined ? 1 : c.opacity}, [0]);
  if (joints >= 0) Plotly.restyle(gd, {visible: !!c.joints}, [joints]);
};
function pick(brick) {
  const rows = [page.name[brick],
                'course ' + page.course[brick] + ', web ' + page.web[brick]
                + (page.solved[brick] ? '' : ' (a turned copy of the solved section)')];
  for (const c of page.colourings) {
    const v = c.values[brick];
    const shown = c.names ? c.names[v]
                          : ((+v.toPrecision(4)).toLocaleString('en') + ' ' + c.unit).trim();
    rows.push(c.label + ': ' + shown);
  }
  document.getElementById('pick').textContent = rows.join('\\n');
}
gd.on('plotly_click', e => {
  const p = e.points[0];
  if (p.curveNumber === 0) pick(owner[p.pointNumber]);
});
"""


_SHARED_PLOTLY = ("<script charset=\"utf-8\" src=\"{src}\" onerror=\"document."
                  "getElementById('pick').textContent = 'plotly.js did not load: this page "
                  "reads it from {src}, beside its run folder (in the output root). Copy "
                  "that file there, or write the page with plotly.js inside it (masonry "
                  "run --html-plotly inline).'\"></script>\n")
"""The page's script tag of the shared plotly.js (``{src}``, relative to the page); a
page copied without it says where it looked and what to do."""


def plotly_file() -> str:
    """The name of the shared plotly.js file, beside the run folders of an output root:
    ``plotly-<version>.min.js``, so that pages written by another plotly read the version
    they were written for."""
    from plotly.offline import get_plotlyjs_version

    return f"plotly-{get_plotlyjs_version()}.min.js"


def plotly_js() -> bytes:
    """The content of :func:`plotly_file`: plotly.js, minified, as plotly ships it."""
    from plotly.offline import get_plotlyjs

    return get_plotlyjs().encode("utf-8")


def outer_faces(blocks, interfaces) -> np.ndarray:
    """(F,) bool: the faces of ``blocks`` not covered
    (:data:`~masonry.tolerances.FACE_COVERED`) by their interfaces with other blocks of
    ``blocks`` (those with images or other blocks of a model, indices
    ``>= blocks.n_blocks``, stay: nothing of them is drawn).

    Each side of an interface lies on the face of its block whose outward normal is the
    interface's normal (the main block) or its opposite (the other block): of a convex
    block, the face whose normal is closest."""
    n = blocks.n_blocks
    inside = (interfaces.pair < n).all(axis=1)
    block = interfaces.pair[inside].T.ravel()  # side 0, then side 1
    outward = np.concatenate([interfaces.normal[inside], -interfaces.normal[inside]])
    order = np.argsort(blocks.face_block, kind="stable")  # faces by block
    first = np.searchsorted(blocks.face_block[order], np.arange(n + 1))
    count = np.diff(first)
    slot = np.arange(count.max())
    faces = order[first[block][:, None] + np.minimum(slot, count[block][:, None] - 1)]
    fit = np.einsum("swk,sk->sw", blocks.face_normal[faces], outward)
    face = faces[np.arange(len(faces)), fit.argmax(axis=1)]
    area = np.tile(interfaces.area[inside], 2)
    covered = np.bincount(face, weights=area, minlength=blocks.n_faces)
    return covered < FACE_COVERED * blocks.face_area


def brick_mesh(blocks, faces) -> tuple:
    """The triangles of ``faces`` ((F,) bool) with only the vertices they use.

    Returns
    -------
    vertices : (V', 3) float32, metres
    triangles : (T', 3) int32
        Into ``vertices``.
    first : (B + 1,) int
        Block ``b`` owns ``vertices[first[b]:first[b + 1]]``.
    """
    triangles = blocks.triangles[faces[blocks.triangle_face]]
    used = np.zeros(len(blocks.vertices), dtype=bool)
    used[triangles.ravel()] = True
    index = np.cumsum(used) - 1
    first = np.concatenate([[0], np.cumsum(used)])[blocks.vertex_offsets]
    return (blocks.vertices[used].astype(np.float32), index[triangles].astype(np.int32),
            first)


def _rounded(values) -> list:
    """Four significant digits: a value printed as the page shows it."""
    values = np.asarray(values, dtype=float)
    return json.loads("[" + ",".join(["%.4g"] * len(values)) % tuple(values) + "]")


def _class_colouring(blocks) -> dict:
    """The brick classes present, each its figures' colour (:data:`CLASS_COLOURS`)."""
    present = np.unique(blocks.block_class)
    names = [BLOCK_CLASSES[k] for k in present]
    steps = [[edge / len(names), CLASS_COLOURS[name]] for i, name in enumerate(names)
             for edge in (i, i + 1)]
    return {"label": "class", "names": names,
            "values": np.searchsorted(present, blocks.block_class).tolist(),
            "style": {"colorscale": steps, "cmin": -0.5, "cmax": len(names) - 0.5,
                      "colorbar": {"title": {"text": "class"}, "len": 0.4,
                                   "tickvals": list(range(len(names))),
                                   "ticktext": names}}}


def _solved_colouring(is_solved) -> dict:
    """The solved section against its turned copies (a cyclic section's whole dome)."""
    names = ["turned copy", "solved section"]
    steps = [[0.0, "#bebebe"], [0.5, "#bebebe"], [0.5, "#c8503c"], [1.0, "#c8503c"]]
    return {"label": "solved section", "names": names,
            "values": np.asarray(is_solved, dtype=int).tolist(),
            "style": {"colorscale": steps, "cmin": -0.5, "cmax": 1.5,
                      "colorbar": {"title": {"text": "solved section", "side": "right"},
                                   "tickvals": [0, 1], "ticktext": names}}}


def _scale_colouring(label, values, free, unit, colorscale, relative=None,
                     noise=0.0) -> dict:
    """``values`` (B,) on a sequential scale from 0 to the :data:`FORCE_PERCENTILE` th
    percentile of the ``free`` bricks' values or, when they are ``relative`` (that
    scale's title), to 1. ``empty`` when no free brick's value exceeds ``noise``: one
    colour says nothing, the page offers it disabled (the picked brick still shows it)."""
    if relative is None:
        top = float(np.percentile(values[free], FORCE_PERCENTILE)) if free.any() else 0.0
        title = f"{label} ({unit}; ends at the {FORCE_PERCENTILE:g}th percentile)"
    else:
        top, title = 1.0, relative
    return {"label": label, "unit": unit, "values": _rounded(values),
            "empty": not (values[free] > noise).any(),
            "style": {"colorscale": colorscale, "cmin": 0.0, "cmax": top or 1.0,
                      "colorbar": {"title": {"text": title, "side": "right"}, "len": 0.8,
                                   "tickformat": "~s" if relative is None else ".1f"}}}


def colourings(made) -> list:
    """The page's colourings of a run (:class:`~masonry.export.RunOutputs`): class; after
    a solve, each brick's largest compression and tension sum over its interfaces
    (:meth:`~masonry.rbe.boundary.Model.block_largest`, those of ``bricks.3dm``); after a
    collapse with a mechanism, each brick's largest vertex displacement (largest 1); on
    a cyclic section's whole dome, the solved section against its turned copies. A
    force none of whose values exceeds
    :data:`~masonry.tolerances.TENSION_REPORTED_REL` of the weight is empty (solver
    noise, the limit of ``RBE/tension_top.csv``)."""
    blocks, model, shown = made.scene.blocks, made.model, made.per_shown
    n, free = blocks.n_blocks, shown(~np.asarray(blocks.block_is_support))
    out = [_class_colouring(made.shown)]
    if made.forces is not None:
        for name, scale in (("compression", "Viridis"), ("tension", "Reds")):
            largest = shown(model.block_largest(made.forces[name])[:n])
            out.append(_scale_colouring(f"largest {name}", largest, free, "N", scale,
                                        noise=TENSION_REPORTED_REL * made.result.weight_N))
    collapse = made.collapse
    if collapse is not None and collapse.mechanism is not None and collapse.load_factor:
        moved = np.linalg.norm(vertex_displacements(model.blocks, collapse.mechanism),
                               axis=1)[:blocks.vertex_offsets[-1]]
        largest = np.zeros(n)
        np.maximum.at(largest, np.repeat(np.arange(n), np.diff(blocks.vertex_offsets)),
                      moved)
        out.append(_scale_colouring(
            "collapse displacement", shown(largest), free, "", "Viridis",
            relative=f"collapse displacement (largest = 1) at lambda = "
                f"{collapse.load_factor:.4g}"))
    if made.adhesion is not None and made.adhesion.a_kPa:
        largest = shown(model.block_largest(made.adhesion.interface_kPa)[:n])
        out.append({"label": "adhesion its joints use", "unit": "kPa", "joints": True,
                    "opacity": JOINTS_SEEN_THROUGH, "values": _rounded(largest),
                    "style": {"colorscale": [[0.0, SEEN_THROUGH], [1.0, SEEN_THROUGH]],
                              "cmin": 0.0, "cmax": 1.0, "colorbar": {}}})
    if not made.is_solved.all():
        out.append(_solved_colouring(made.is_solved))
    return out


def adhesion_trace(model, adhesion):
    """The joints that use adhesion at the least adhesion's optimum (more than
    :data:`~masonry.tolerances.ADHESION_REPORTED_REL` of ``a*``), as one plotly
    ``Mesh3d`` named ``joints`` (hidden until the page's colouring ``adhesion its joints
    use`` shows it): each joint's polygon a fan of triangles of its own vertices, coloured
    by the kPa it uses (float64, the values of ``RBE/adhesion.csv``) on the figures'
    magnitude map from 0 to the largest, its hover text naming its two blocks and the
    kPa. Of a cyclic section, the solved section's joints only (the page stays small)."""
    import plotly.graph_objects as go

    interfaces, used = model.interfaces, np.asarray(adhesion.interface_kPa, dtype=float)
    chosen = np.flatnonzero(used > ADHESION_REPORTED_REL * adhesion.a_kPa)
    start, count = interfaces.offsets[chosen], np.diff(interfaces.offsets)[chosen]
    first = np.concatenate([[0], np.cumsum(count)])
    owner = np.repeat(np.arange(len(chosen)), count)
    vertices = interfaces.vertices[start[owner] + np.arange(first[-1]) - first[owner]]
    fan = np.repeat(np.arange(len(chosen)), count - 2)  # polygon k: count - 2 triangles
    step = np.arange(len(fan)) - (first[fan] - 2 * fan)
    triangles = np.column_stack([first[fan], first[fan] + step + 1, first[fan] + step + 2])
    names = model.blocks.block_name[interfaces.pair[chosen]]
    text = [f"{a} | {b}: {value:.4g} kPa" for (a, b), value in zip(names, used[chosen])]
    return go.Mesh3d(x=vertices[:, 0], y=vertices[:, 1], z=vertices[:, 2],
                     i=triangles[:, 0], j=triangles[:, 1], k=triangles[:, 2],
                     intensity=used[chosen][owner], intensitymode="vertex",
                     colorscale="Viridis", cmin=0.0, cmax=float(used.max()),
                     colorbar={"title": {"text": "adhesion the joint uses (kPa)",
                                         "side": "right"}, "len": 0.8},
                     hovertext=[text[k] for k in owner], hoverinfo="text",
                     flatshading=True, name="joints", visible=False)


def _arrow_traces(live, model, bounds) -> list:
    """The live load's direction: a line and a cone at its head, or nothing. A body
    force's comes from outside the structure's box ``bounds``; one into loaded blocks may
    start out of it by a quarter of its size (the page's first view shows it too)."""
    import plotly.graph_objects as go

    if live.loaded_blocks(model.blocks) is not None:
        bounds = bounds + np.array([[-0.25], [0.25]]) * (bounds[1] - bounds[0])
    arrow = live.arrow(model.blocks, bounds, outside=True)
    if arrow is None:
        return []
    start, end = arrow
    tip = end - start
    return [go.Scatter3d(x=[start[0], end[0]], y=[start[1], end[1]], z=[start[2], end[2]],
                         mode="lines", line=dict(color="black", width=6),
                         name="live load", hoverinfo="name", showlegend=False),
            go.Cone(x=[end[0]], y=[end[1]], z=[end[2]], u=[tip[0]], v=[tip[1]], w=[tip[2]],
                    anchor="tip", sizemode="absolute",
                    sizeref=0.25 * float(np.linalg.norm(tip)), showscale=False,
                    colorscale=[[0, "black"], [1, "black"]], name="live load",
                    hoverinfo="name")]


def camera(points) -> dict:
    """plotly's camera of the first view of ``points`` ((N, 3), metres; all a page
    draws): from :data:`VIEW`, towards the middle of their picture, as near as lets every
    point into :data:`FIT` of the plot.

    plotly draws a scene's box scaled by the geometric mean of its sides (``aspectmode
    "data"``) around the origin; a point ``p`` there (from the camera's ``center``) is
    seen at ``(p . right, p . up) / (distance - p . eye) / tan(FOVY / 2)`` of the plot's
    half height. Moving ``center`` by the picture's middle centres it (a few rounds: the
    perspective changes as it moves)."""
    low, high = points.min(axis=0), points.max(axis=0)
    size = float(np.prod(np.maximum(high - low, 1e-9 * (high - low).max())) ** (1 / 3))
    p = (points - (low + high) / 2) / size
    azimuth, elevation = np.radians(VIEW)
    eye = np.array([np.cos(elevation) * np.cos(azimuth),
                    np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])
    screen = np.array([[-np.sin(azimuth), np.cos(azimuth), 0.0], [0.0, 0.0, 0.0]])
    screen[1] = np.cross(eye, screen[0])  # right, up
    reach = FIT * np.tan(FOVY / 2) * np.array([[FIT_ASPECT, 1.0]])
    centre = np.zeros(3)
    for _ in range(4):
        seen = p - centre
        distance = (seen @ eye + (np.abs(seen @ screen.T) / reach).max(axis=1)).max()
        picture = (seen @ screen.T) / (distance - seen @ eye)[:, None]
        middle = (picture.max(axis=0) + picture.min(axis=0)) / 2
        centre = centre + distance * middle @ screen
    return {"center": dict(zip("xyz", centre.tolist())),
            "eye": dict(zip("xyz", (centre + distance * eye).tolist()))}


def dome_html(made) -> str:
    """The page of a run (:class:`~masonry.export.RunOutputs`): its scene's bricks
    (:func:`outer_faces` only), coloured by each of :func:`colourings` in turn, the live
    load's direction as an arrow, and a picked brick's name, course, web and values;
    plotly.js inside it, or read from :func:`plotly_file` in the output root, as the
    run's ``outputs.html_plotly`` says."""
    import plotly.graph_objects as go

    blocks = made.shown
    # a turned copy's faces are seen where its section block's are (cyclic symmetry)
    faces = np.tile(outer_faces(made.scene.blocks, made.model.interfaces),
                    blocks.n_blocks // made.scene.blocks.n_blocks)
    vertices, triangles, first = brick_mesh(blocks, faces)
    shown = colourings(made)
    owner = np.repeat(np.arange(blocks.n_blocks), np.diff(first))
    mesh = go.Mesh3d(x=vertices[:, 0], y=vertices[:, 1], z=vertices[:, 2],
                     i=triangles[:, 0], j=triangles[:, 1], k=triangles[:, 2],
                     intensity=np.asarray(shown[0]["values"], dtype=np.float32)[owner],
                     intensitymode="vertex", flatshading=True, hoverinfo="none",
                     lighting=dict(ambient=0.8, diffuse=0.45, specular=0.05),
                     lightposition=dict(x=1e5, y=-1e5, z=1e5),
                     **shown[0]["style"])
    live = made.collapse.live if made.collapse is not None else None
    arrows = [] if live is None else _arrow_traces(live, made.model, blocks.bounds)
    drawn = np.concatenate([vertices, *(np.column_stack([a.x, a.y, a.z]) for a in arrows)])
    hidden = dict(visible=False)
    joints = ([adhesion_trace(made.model, made.adhesion)]
              if made.adhesion is not None and made.adhesion.a_kPa else [])
    fig = go.Figure([mesh, *arrows, *joints])
    fig.update_layout(template="none", margin=dict(l=0, r=0, t=0, b=0),
                      scene=dict(aspectmode="data", xaxis=hidden, yaxis=hidden,
                                 zaxis=hidden, camera=camera(drawn)))
    shared = made.outputs.html_plotly == "shared"
    plot = fig.to_html(full_html=False, include_plotlyjs=not shared, default_width="100%",
                       default_height="100%", config={"displaylogo": False},
                       post_script=_SCRIPT)
    if shared:  # the run folder is one level below the output root
        plot = _SHARED_PLOTLY.format(src=html.escape(f"../{plotly_file()}")) + plot
    bricks = {"first": first.tolist(), "name": blocks.block_name.tolist(),
              "course": blocks.block_course.tolist(), "web": blocks.block_web.tolist(),
              "solved": made.is_solved.tolist(), "colourings": shown}
    data = json.dumps(bricks, separators=(",", ":"), allow_nan=False)
    return _PAGE.format(title=html.escape(made.figure_title), plot=plot,
                        bricks=data.replace("</", "<\\/"))
