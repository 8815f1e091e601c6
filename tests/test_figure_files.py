"""The files a figure becomes (PNG, SVG, PDF at a chosen resolution), from the command
line to run.json, and one colour per concept across the figures."""

import io
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import PIL.Image
import pytest
from matplotlib.colors import to_rgb

from cli.main import main
from masonry.blocks import CLASS_COLOURS
from masonry.params import Params, from_preset, validate
from masonry.pipeline import build_model
from masonry.plots import Render, colours, common, pattern, stages, structure


def _figure():
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [0, 1], label="a line")
    ax.set_xlabel("x [m]")
    ax.legend()
    return fig


def test_each_format_asked_is_written_and_opens():
    files = common.figure_files(_figure(), 100, Render(("png", "svg", "pdf")))
    assert list(files) == ["png", "svg", "pdf"]
    assert PIL.Image.open(io.BytesIO(files["png"])).format == "PNG"
    root = ET.fromstring(files["svg"])
    assert root.tag.endswith("svg")
    # text as text (svg.fonttype 'none'): the axis label is a <text> element, not paths
    texts = [e.text for e in root.iter() if e.tag.endswith("text")]
    assert "x [m]" in texts
    assert files["pdf"].startswith(b"%PDF")


def test_the_dpi_sets_the_pngs_pixel_size():
    """The same figure at 200 dpi is twice as many pixels each way as at 100 (within the
    crop's rounding, a pixel at either end), and the render's dpi replaces the
    figure's own."""
    own = PIL.Image.open(io.BytesIO(common.figure_files(_figure(), 100)["png"])).size
    asked = common.figure_files(_figure(), 100, Render(("png",), 200))["png"]
    double = PIL.Image.open(io.BytesIO(asked)).size
    assert all(abs(d - 2 * o) <= 2 for d, o in zip(double, own))
    assert 300 <= own[0] <= 400 and 225 <= own[1] <= 300  # 4 x 3 inches, cropped


def test_a_run_writes_every_figure_in_the_formats_asked_and_lists_them(tmp_path):
    assert main(["run", "--scene", "arch", "--figure-format", "svg", "--figure-format",
                 "pdf", "--dpi", "60", "--no-printable", "--no-html", "--out",
                 str(tmp_path), "-q"]) == 0
    (folder,) = tmp_path.glob("arch_*")
    record = json.loads((folder / "run.json").read_text())
    listed = record["figures"]["files"]
    assert record["outputs"]["figure_format"] == ["svg", "pdf"]
    assert not list(folder.rglob("*.png"))
    stems = {Path(name).with_suffix("") for name in listed}
    assert {name for name in listed} == {f"{s}.{f}" for s in stems for f in ("svg", "pdf")}
    assert "RBE/thrust_line.svg" in listed
    for name in listed:
        data = (folder / name).read_bytes()
        assert data.startswith(b"%PDF") if name.endswith(".pdf") else \
            ET.fromstring(data).tag.endswith("svg")


def test_a_folder_without_a_format_asked_is_not_reused(tmp_path):
    base = ["run", "--scene", "arch", "--no-printable", "--no-html", "--out",
            str(tmp_path), "-q"]
    assert main([*base, "--dpi", "60"]) == 0
    assert main([*base, "--dpi", "60", "--figure-format", "pdf"]) == 0
    (folder,) = tmp_path.glob("arch_*")
    record = json.loads((folder / "run.json").read_text())
    assert not record.get("reused")
    # the folder grows: the PNGs it held are written again beside the PDFs
    assert set(record["outputs"]["figure_format"]) == {"png", "pdf"}
    assert (folder / "RBE/thrust_line.png").exists() and (folder / "RBE/thrust_line.pdf").exists()


@pytest.mark.parametrize("args, line", [
    (["--figure-format", "tiff"], "--figure-format tiff: expected one or more of png, svg, "
                                  "pdf"),
    (["--dpi", "10"], "--dpi 10: expected an integer 50 to 600"),
    (["--dpi", "601"], "--dpi 601: expected an integer 50 to 600"),
])
def test_a_bad_figure_option_gets_one_line_and_writes_nothing(tmp_path, capsys, args, line):
    assert main(["run", "--scene", "arch", *args, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and line in err[0]
    assert not (tmp_path / "out").exists()


@pytest.fixture
def drawn(monkeypatch):
    """The figures the plot modules save, kept open instead of saved."""
    kept = []

    def keep(fig, dpi, render=None, close=True):
        kept.append(fig)
        return {"png": b""}

    for module in (pattern, structure, stages):
        monkeypatch.setattr(module, "figure_files", keep)
    yield kept
    plt.close("all")


def _face_colours(fig) -> set:
    return {tuple(np.round(c[:3], 4)) for ax in fig.axes for artist in ax.collections
            for c in np.atleast_2d(artist.get_facecolor())}


def test_each_concept_has_one_colour_in_every_figure(drawn):
    """The pattern bricks are the same RGB in the flattened pattern and the structure
    views; a stage that needs support, one that stands and a loose block are drawn in
    colours of their own, none of them a block class's."""
    params = validate(Params.of(**{**from_preset("3").record(), "p": 4}))
    scene, model = build_model(params)
    pattern.pattern_png(scene)
    structure.structure_pngs(scene, fast=True, interfaces=model.interfaces)
    stages.stage_chart_png([1, 2, 3], [0.0, 0.2, 0.3], [True, False, False],
                           loose=[0, 0, 1])
    *block_figures, chart = drawn
    pattern_rgb = tuple(np.round(to_rgb(CLASS_COLOURS["pattern"]), 4))
    assert all(pattern_rgb in _face_colours(fig) for fig in block_figures[:1] +
               [f for f in block_figures[1:] if "pattern" in f.axes[0].get_title()])
    by_label = {c.get_label().split(" (")[0]: tuple(np.round(c.get_facecolor()[0][:3], 4))
                for c in chart.axes[0].collections}
    stands = tuple(np.round(to_rgb(colours.STANDS), 4))
    needs = tuple(np.round(to_rgb(colours.NEEDS_SUPPORT), 4))
    assert by_label["stands"] == stands and by_label["needs support"] == needs
    classes = {tuple(np.round(to_rgb(c), 4)) for c in CLASS_COLOURS.values()}
    assert len({stands, needs, tuple(np.round(to_rgb(colours.LOOSE), 4))}) == 3
    assert not {stands, needs} & classes
