"""``dome.html`` (masonry/export/html.py): what the page holds for every scene, the
run-folder protocol's view of it, and the page in a real headless browser (Chromium,
driven by Playwright), skipped with the reason where either is missing."""

import csv
import io
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from masonry.blocks import Blocks, whole_of_web
from masonry.export.html import brick_mesh, outer_faces, plotly_file
from masonry.interfaces import detect
from masonry.params import Params, validate
from masonry.pipeline import run
from masonry.scenes import build
from masonry.scenes.imported import load_assembly
from masonry.tolerances import Tolerances

ARTEFACTS = Path(os.environ.get("MASONRY_TEST_ARTEFACTS",
                               Path(__file__).resolve().parent.parent / "exports"
                               / "test_artefacts"))
"""Where the browser test leaves its screenshot of preset 1's full dome (under the
output root, not committed), for a reader or a CI job to keep."""
CHROMIUM = next(filter(None, map(shutil.which, ("chromium", "chromium-browser",
                                                "google-chrome"))), None)
# as root, and with no network: no sandbox, no background connections (docs/outputs.md)
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"]
SMALL = {
    "section": dict(scene="section", boundary="cyclic", fast=True),
    "free section": dict(scene="section", boundary="free", p=3, fast=True),  # in tension
    "wall": dict(scene="wall", wall_length=8, wall_courses=3, fast=True),
    "arch": dict(scene="arch", fast=True, point_loads=("v006:0,0,-50000",)),
    "revolution": dict(scene="revolution", radius=20, p=3, cut=0.3, fast=True),
    "sector": dict(scene="sector", radius=20, p=3, cut=0.3, boundary="cyclic", fast=True),
}


def page_data(path) -> dict:
    """The bricks' data the page's script reads."""
    text = path.read_text()
    return json.loads(re.search(r'<script id="bricks" type="application/json">(.*?)'
                                r'</script>', text, re.S)[1])


def quick_run(out, html=True, built=None, **inputs) -> dict:
    """``masonry run`` of ``inputs`` (or of the scene ``built``) into ``out``: no plots,
    no printable body."""
    params = validate(Params.of(**inputs, plots=False, printable=False, html=html))
    return run(params, out, scene=built)


def two_boxes(shift):
    """A unit box on the ground slab, and a second one on it moved ``shift`` along x."""
    box = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
    slab = box * [3, 3, 0.5] - [1, 1, 0.5]
    return Blocks.from_hexahedra([slab, box, box + [shift, 0, 1]],
                                 ["ground", "regular", "regular"])


def test_faces_wholly_in_contact_are_not_drawn():
    """Two boxes stacked flush share their whole beds: neither bed is drawn, nor the
    slab's face under the lower box (the slab's top is larger: it stays); moved half a
    box, the upper box's bed and the lower one's top are partly open: drawn."""
    for shift, hidden in ((0.0, 3), (0.5, 1)):
        blocks = two_boxes(shift)
        faces = outer_faces(blocks, detect(blocks, Tolerances(scale=3.0)))
        assert (~faces).sum() == hidden
        vertices, triangles, first = brick_mesh(blocks, faces)
        assert first.tolist() == [0, 8, 16, 24]  # every corner is on some drawn face
        assert len(triangles) == 2 * faces.sum() and triangles.max() < len(vertices)


@pytest.mark.parametrize("scene", sorted(SMALL))
def test_every_scene_writes_the_page(tmp_path, scene):
    """One page per run, reading plotly.js from the one file beside the run folders (no
    other address to fetch), that names every brick of the scene and colours it by class
    and, after the solve, by its largest compression and tension; after a collapse with a
    mechanism by its displacement, with the live load's arrow."""
    record = quick_run(tmp_path, **SMALL[scene])
    path = tmp_path / record["structure_id"] / "dome.html"
    text = path.read_text()
    assert re.findall(r"<script[^>]+src=\"([^\"]+)\"", text) == [f"../{plotly_file()}"]
    assert "Plotly.newPlot" in text
    data = page_data(path)
    built = build(validate(Params.of(**SMALL[scene])))
    blocks = built.blocks
    if record["params"]["boundary"] == "cyclic":  # the whole dome the section stands for
        blocks = whole_of_web(blocks, built.symmetry.order)
        assert data["solved"] == (np.arange(blocks.n_blocks)
                                  < built.blocks.n_blocks).tolist()
    assert data["name"] == blocks.block_name.tolist()
    assert data["course"] == blocks.block_course.tolist()
    labels = [c["label"] for c in data["colourings"]]
    assert labels[:3] == ["class", "largest compression", "largest tension"]
    for colouring in data["colourings"]:
        assert len(colouring["values"]) == len(data["name"])
    # no tension worth a colour exactly when RBE/tension_top.csv lists no joint
    with open(path.parent / "RBE" / "tension_top.csv", newline="") as table:
        listed = list(csv.DictReader(table))
    assert data["colourings"][2]["empty"] is (not listed)
    if listed:  # its largest joint's tension is some brick's largest
        assert max(data["colourings"][2]["values"]) == pytest.approx(
            max(float(row["tension_N"]) for row in listed), rel=1e-3)
    assert record["outputs"]["html"] is True
    if scene == "arch":
        assert labels[3] == "collapse displacement"
        assert max(data["colourings"][3]["values"]) == pytest.approx(1, abs=1e-3)
        assert '"type":"cone"' in text


def test_an_assembly_and_a_build_write_the_page(tmp_path, fixtures_dir):
    """Blocks read from files get their page; a build (no solve) colours by class only."""
    scene, _ = load_assembly([fixtures_dir / "assembly" / "arch_rhino.obj"],
                             supports=["pier_*"])
    record = quick_run(tmp_path, built=scene, scene="assembly",
                       assembly=scene.geometry.assembly)
    names = page_data(tmp_path / record["structure_id"] / "dome.html")["name"]
    assert sorted(names) == sorted(str(n) for n in scene.blocks.block_name)
    params = validate(Params.of(**SMALL["wall"], plots=False, printable=False, html=True))
    record = run(params, tmp_path / "build", analyse=False)
    data = page_data(tmp_path / "build" / record["structure_id"] / "dome.html")
    assert [c["label"] for c in data["colourings"]] == ["class"]


def test_a_folder_without_the_page_is_not_up_to_date(tmp_path):
    """A folder written with --no-html does not hold what a run asking for the page
    wants: the run writes it; the next run, with or without the page, reuses the folder
    (it only grows)."""
    first = quick_run(tmp_path, html=False, **SMALL["wall"])
    folder = tmp_path / first["structure_id"]
    assert not (folder / "dome.html").exists() and first["outputs"]["html"] is False
    second = quick_run(tmp_path, **SMALL["wall"])
    assert not second.get("reused") and (folder / "dome.html").is_file()
    assert quick_run(tmp_path, **SMALL["wall"]).get("reused")
    assert quick_run(tmp_path, html=False, **SMALL["wall"]).get("reused")


def test_the_page_follows_the_figures_unless_asked(tmp_path):
    """Without ``html`` the page is written with the figures; ``html`` says otherwise
    either way."""
    wall = dict(SMALL["wall"], printable=False)
    for plots, html, written in ((False, None, False), (True, None, True),
                                 (False, True, True), (True, False, False)):
        record = run(validate(Params.of(**wall, plots=plots, html=html)), tmp_path / "out",
                     analyse=False, force=True)
        assert record["outputs"]["html"] is written, (plots, html)
        path = tmp_path / "out" / record["structure_id"] / "dome.html"
        assert path.is_file() is written, (plots, html)
        shutil.rmtree(tmp_path / "out")


def test_the_pages_of_an_output_root_share_one_plotly(tmp_path):
    """Two runs into one root: one plotly.js file beside them, as plotly ships it (read
    back), each page small (plotly.js is 4.8 MB) and reading it; asked ``inline``, the
    page holds plotly.js itself, and a shared page is not the one asked for (written
    again), while an inline page stands for a shared one (reused)."""
    from plotly.offline import get_plotlyjs

    for p in (3, 4):
        quick_run(tmp_path, **SMALL["free section"] | {"p": p})
    assert [f.name for f in tmp_path.glob("plotly*")] == [plotly_file()]
    assert (tmp_path / plotly_file()).read_text() == get_plotlyjs()
    pages = sorted(tmp_path.glob("*/dome.html"))
    assert len(pages) == 2 and all(page.stat().st_size < 0.5e6 for page in pages)
    params = validate(Params.of(**SMALL["wall"], plots=False, printable=False, html=True))
    first = run(params, tmp_path)
    page = tmp_path / first["structure_id"] / "dome.html"
    inline = run(params.replace(html_plotly="inline"), tmp_path)
    assert not inline.get("reused") and inline["outputs"]["html_plotly"] == "inline"
    text = page.read_text()
    assert not re.search(r"<script[^>]+src=", text) and get_plotlyjs() in text
    assert run(params, tmp_path).get("reused")


# --------------------------------------------------------------------------- browser
@pytest.fixture(scope="module")
def browser():
    if CHROMIUM is None:
        pytest.skip("no Chromium on this machine (Debian: apt-get install chromium)")
    sync_api = pytest.importorskip(
        "playwright.sync_api", reason="Playwright is not installed (pip install "
                                      "'masonry[test]'; it drives the system's Chromium)")
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield browser
        browser.close()


def open_page(browser, path):
    """The page loaded and drawn, and the errors it logged meanwhile."""
    page = browser.new_page(viewport={"width": 1000, "height": 750})
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda error: errors.append(str(error)))
    page.goto(path.as_uri())
    page.wait_for_function("document.querySelector('.js-plotly-plot canvas') !== null "
                           "&& document.querySelector('.js-plotly-plot')._fullLayout")
    page.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
    return page, errors


def drawn(png) -> np.ndarray:
    """(H, W) bool: a screenshot's pixels that are not the white background."""
    from PIL import Image

    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=int)
    return pixels.sum(axis=2) < 3 * 250


def drawn_fraction(png) -> float:
    """The fraction of a screenshot's pixels that are not the white background."""
    return float(drawn(png).mean())


def picture_box(page) -> tuple:
    """The part of the plot left of the colour bar, as ``(top, bottom, left, right)``
    pixels, and the drawn pixels' box in it as fractions of its height and width."""
    plot = page.locator("#plot").bounding_box()
    bar = page.locator(".js-plotly-plot .colorbar").first.bounding_box()
    top, bottom = round(plot["y"]), round(plot["y"] + plot["height"])
    left, right = round(plot["x"]), round(bar["x"])
    rows, columns = np.nonzero(drawn(page.screenshot())[top:bottom, left:right])
    return ((rows.min() / (bottom - top), rows.max() / (bottom - top)),
            (columns.min() / (right - left), columns.max() / (right - left)))


def click(page, x, y) -> str:
    """Press and release the mouse at (x, y) (plotly picks while the button is down, on
    its next frame) and return the picked brick's panel."""
    page.mouse.move(x, y)
    page.wait_for_timeout(100)
    page.mouse.down()
    page.wait_for_timeout(150)
    page.mouse.up()
    page.wait_for_timeout(100)
    return page.inner_text("#pick")


def test_the_dome_turns_and_picks_in_a_browser(browser, tmp_path_factory):
    """Preset 1's whole dome (6,320 bricks) in headless Chromium: the page loads without
    an error, the first view shows the whole dome, large and not clipped, a click on a
    brick shows its name, course and forces, and every colouring draws (the tension of
    this feasible dome is none: not offered). The screenshot, a brick picked, goes to
    :data:`ARTEFACTS`."""
    out = tmp_path_factory.mktemp("html")
    record = quick_run(out, scene="dome")
    path = out / record["structure_id"] / "dome.html"
    assert path.stat().st_size < 15e6
    names = set(page_data(path)["name"])
    page, errors = open_page(browser, path)
    (top, bottom), (left, right) = picture_box(page)
    assert 0.01 < top and bottom < 0.99 and 0.01 < left and right < 0.99  # not clipped
    assert bottom - top > 0.6 and right - left > 0.6  # not lost in the middle
    assert abs((top + bottom) / 2 - 0.5) < 0.1 and abs((left + right) / 2 - 0.5) < 0.1
    box = page.locator(".js-plotly-plot canvas").first.bounding_box()
    panel = ""
    for dx, dy in ((0.45, 0.55), (0.5, 0.7), (0.35, 0.6), (0.6, 0.5)):
        panel = click(page, box["x"] + dx * box["width"], box["y"] + dy * box["height"])
        if panel:
            break
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    shot = page.screenshot(path=str(ARTEFACTS / "preset1_dome_html.png"))
    assert drawn_fraction(shot) > 0.1
    lines = panel.splitlines()
    assert lines and lines[0] in names, panel
    assert re.match(r"course \d+, web \d+$", lines[1])
    assert any(line.startswith("largest compression: ") and line.endswith(" N")
               for line in lines)
    options = page.locator("#colouring option")
    assert options.all_inner_texts() == ["class", "largest compression",
                                         "largest tension: none"]
    assert page.locator("#colouring option:disabled").all_inner_texts() == [
        "largest tension: none"]
    page.select_option("#colouring", label="largest compression")
    page.evaluate("new Promise(r => requestAnimationFrame(r))")
    assert drawn_fraction(page.screenshot()) > 0.1
    assert errors == []
    page.close()


def test_the_mechanism_and_the_load_show_in_a_browser(browser, tmp_path):
    """An arch at collapse under a point load: its page loads without an error and
    colours by the mechanism."""
    record = quick_run(tmp_path, **SMALL["arch"])
    page, errors = open_page(browser, tmp_path / record["structure_id"] / "dome.html")
    page.select_option("#colouring", label="collapse displacement")
    page.evaluate("new Promise(r => requestAnimationFrame(r))")
    assert drawn_fraction(page.screenshot()) > 0.01
    assert errors == []
    page.close()


def test_a_page_copied_without_plotly_says_where_it_looked(browser, tmp_path):
    """A run folder copied alone: its page draws nothing and says which file it reads
    plotly.js from; the same page with plotly.js inside draws anywhere."""
    for source in ("shared", "inline"):
        params = validate(Params.of(**SMALL["wall"], plots=False, printable=False,
                                    html=True, html_plotly=source))
        record = run(params, tmp_path / source)
        copy = tmp_path / "copies" / source
        shutil.copytree(tmp_path / source / record["structure_id"], copy)
        page = browser.new_page()
        page.goto((copy / "dome.html").as_uri())
        page.wait_for_load_state("load")
        drawn_plot = page.evaluate("document.querySelector('.js-plotly-plot') !== null")
        assert drawn_plot is (source == "inline")
        if source == "shared":
            assert f"../{plotly_file()}" in page.inner_text("#pick")
        page.close()
