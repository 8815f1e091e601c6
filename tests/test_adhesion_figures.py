"""The joints coloured by the adhesion they use at the least adhesion's optimum
(docs/outputs.md, docs/model.md 6.12): the figure's scale and colours, the files a run
writes where it needs adhesion (and not where it stands dry), the figure of the stage
where the least adhesion peaks, and dome.html's layer of the joints."""

import base64
import json
import re
import xml.etree.ElementTree as ET

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import PIL.Image
import pytest
from matplotlib.colors import to_rgba

import masonry
from masonry.params import Params, validate
from masonry.pipeline import build_model
from masonry.plots import forces as force_figures
from masonry.plots.colours import NO_ADHESION
from masonry.plots.common import Projected
from masonry.rbe.adhesion import least_adhesion
from masonry.rbe.boundary import restrict
from masonry.stages.analysis import analyse_stages
from masonry.stages.plans import make_plan
from masonry.stages.run import peak_adhesion_pngs
from masonry_cli.main import main

THIN = validate(Params.of(scene="arch", arch_thickness=0.4))
"""A closed arch thinner than its least thickness (t/R 0.08 < 0.1075, tests/
test_adhesion.py): it needs adhesion, at its four hinges most."""

VIEWS = ("01_angle", "04_side")
"""The views of an arch: the 3D one and its face (the other elevations see it edge on)."""


def _least(model, params):
    analysis = params.analysis
    return least_adhesion(model, mu=analysis.mu, density=analysis.density,
                          cone=analysis.cone, ratio=analysis.adhesion_tension_ratio)


@pytest.fixture(scope="module")
def thin_arch():
    _, model = build_model(THIN)
    return model, _least(model, THIN)


@pytest.fixture
def drawn(monkeypatch):
    """Per figure saved: the colour bar's range and, in the order given, the colours of
    the joints of each filled collection of an elevation (those dry friction holds,
    then those that use adhesion)."""
    kept = []

    def keep(fig, dpi, render=None, close=True):
        fig.canvas.draw()
        ax, bar = fig.axes[0], fig.axes[1]
        joints = [c for c in ax.collections if isinstance(c, Projected)
                  and (c.get_facecolor()[:, 3] > 0).all()]
        colours = [c.get_facecolor()[np.argsort(c.order)] for c in joints]
        kept.append((bar.get_ylim(), colours))
        plt.close(fig)
        return {"png": b"\x89PNG kept"}

    monkeypatch.setattr(force_figures, "figure_files", keep)
    return kept


def test_the_bar_spans_zero_to_the_largest_use_and_the_top_joint_has_the_top_colour(
        thin_arch, drawn):
    """The colour bar runs from 0 to the largest adhesion a joint uses (no percentile,
    to 1e-9); the joint that uses most is the map's top colour, every joint that uses
    adhesion its share of the largest on the map, the joints dry friction holds (at most
    1e-3 of a*) light grey; a figure per view of the arch."""
    model, result = thin_arch
    used = result.interface_kPa
    top = used.max()
    assert top == pytest.approx(result.a_kPa, rel=1e-4)  # some joint uses all of a*
    files = force_figures.adhesion_pngs(model.blocks, model.interfaces, used, result.a_kPa)
    assert sorted(files) == [f"{view}.png" for view in VIEWS]
    (low, high), _ = drawn[0]
    assert (low, high) == (0.0, pytest.approx(top, rel=1e-9))
    _, (held, using) = drawn[1]  # the arch's face
    viridis = matplotlib.colormaps["viridis"]
    uses = used > 1e-3 * result.a_kPa
    assert 0 < uses.sum() < len(used)
    assert using[np.argmax(used[uses])] == pytest.approx(np.array(viridis(1.0)), abs=1e-12)
    assert using == pytest.approx(viridis(used[uses] / top), abs=1e-12)
    assert held == pytest.approx(np.tile(to_rgba(NO_ADHESION), ((~uses).sum(), 1)))


def test_the_stage_where_the_adhesion_peaks_is_drawn_from_its_own_program(drawn):
    """The default arch laid in pairs from the springings needs most adhesion at stage 7
    (two cantilevers, tests/test_stage_adhesion.py): its figure's joints are the stage's
    own (both blocks laid) and its bar ends at the largest use of the program solved on
    that stage's model alone (two interior point solves: rel 1e-4)."""
    params = validate(Params.of(scene="arch", plots=True))
    scene, model = build_model(params)
    plan = make_plan(scene, "block", "z")
    rows = analyse_stages(model, params, plan)
    files = peak_adhesion_pngs(params, "arch", model, plan, rows)
    assert sorted(files) == [f"adhesion_peak/{view}.png" for view in VIEWS]
    part = restrict(model, plan.is_present(7))
    alone = _least(part, params)
    (low, high), _ = drawn[0]
    assert low == 0.0 and high == pytest.approx(alone.interface_kPa.max(), rel=1e-4)
    _, colours = drawn[1]
    assert sum(len(c) for c in colours) == len(part.interfaces)


def _traces(path) -> list:
    """The plotly traces of a page, as the page's script hands them to plotly."""
    text = path.read_text()
    start = re.search(r"Plotly\.newPlot\(\s*\"[^\"]+\",\s*", text).end()
    return json.JSONDecoder().raw_decode(text[start:])[0]


def _array(value) -> np.ndarray:
    """A plotly array: a list, or a typed array written as base64."""
    if isinstance(value, dict):
        return np.frombuffer(base64.b64decode(value["bdata"]), dtype=value["dtype"])
    return np.asarray(value)


def test_a_run_that_needs_adhesion_writes_its_joints_figure_and_page_layer(tmp_path):
    """``masonry run`` of the thin arch at --dpi 60 in PNG and SVG: the figure of every
    view, listed in run.json, the PNG as many pixels as the SVG's size in points at 60
    per 72 (within 2 %: text is measured at each resolution, and the crop follows it);
    dome.html's ``joints`` trace holds the joints RBE/adhesion.csv says use adhesion
    (more than 1e-3 of a*), each with its kPa to 1e-9 (the CSV's digits) and named by
    its blocks, on a bar from 0 to the largest; the page offers the colouring that
    shows it."""
    assert main(["run", "--scene", "arch", "--thickness", "0.4", "--dpi", "60",
                 "--figure-format", "png,svg", "--no-printable", "--out", str(tmp_path),
                 "-q"]) == 0
    (folder,) = tmp_path.glob("arch_*")
    listed = json.loads((folder / "run.json").read_text())["figures"]["files"]
    for view in VIEWS:
        for suffix in ("png", "svg"):
            assert f"RBE/{view}/adhesion.{suffix}" in listed
            assert (folder / "RBE" / view / f"adhesion.{suffix}").is_file()
    size = np.array(PIL.Image.open(folder / "RBE" / "04_side" / "adhesion.png").size)
    svg = ET.parse(folder / "RBE" / "04_side" / "adhesion.svg").getroot()
    points = np.array([float(svg.get(side).removesuffix("pt")) for side in ("width",
                                                                            "height")])
    assert size == pytest.approx(points * 60 / 72, rel=0.02)  # not 110 dpi's, 1.8 times

    table = masonry.read_table(folder / "RBE" / "adhesion.csv")
    a = json.loads((folder / "run.json").read_text())["adhesion"]["a_kPa"]
    uses = table[table["adhesion_kPa"] > 1e-3 * a]
    (joints,) = [t for t in _traces(folder / "dome.html") if t.get("name") == "joints"]
    assert joints["visible"] is False and joints["cmin"] == 0.0
    assert joints["cmax"] == pytest.approx(table["adhesion_kPa"].max(), rel=1e-9)
    text, value = joints["hovertext"], _array(joints["intensity"])
    shown = {}
    for label, kPa in zip(text, value):  # every vertex of a joint carries its value
        shown.setdefault(label.split(":")[0], set()).add(float(kPa))
    expected = {f"{a} | {b}": kPa for a, b, kPa
                in zip(uses["name_a"], uses["name_b"], uses["adhesion_kPa"])}
    assert set(shown) == set(expected)
    for joint, kPa in expected.items():
        (got,) = shown[joint]
        assert got == pytest.approx(kPa, rel=1e-9)
    page = json.loads(re.search(r'<script id="bricks" type="application/json">(.*?)'
                                r'</script>', (folder / "dome.html").read_text(), re.S)[1])
    assert "adhesion its joints use" in [c["label"] for c in page["colourings"]]


def test_a_run_that_stands_dry_has_neither(tmp_path):
    """The default arch stands with dry joints (a* = 0): no joints figure, no layer."""
    assert main(["run", "--scene", "arch", "--fast", "--no-printable", "--out",
                 str(tmp_path), "-q"]) == 0
    (folder,) = tmp_path.glob("arch_*")
    assert json.loads((folder / "run.json").read_text())["adhesion"]["a_kPa"] == 0.0
    assert not list(folder.rglob("adhesion.png"))
    assert "joints" not in [t.get("name") for t in _traces(folder / "dome.html")]
