"""Fuzz of the Python interface and of what it reads back.

Every bad argument of :func:`masonry.build`, :func:`masonry.read`,
:func:`masonry.read_table` and of a structure's methods raises
:class:`~masonry.errors.MasonryError` (or a subclass) with a one-line message, never a
TypeError or a bare ValueError; a number of numpy's is a number; every table the project
writes reads back typed.
"""

import numpy as np
import pytest
import trimesh

import masonry
from masonry.errors import MasonryError
from masonry.export.csv import _table
from masonry.stages.analysis import STAGE_COLUMNS
from masonry.stages.run import stages_csv


@pytest.fixture(scope="module")
def tower(tmp_path_factory):
    """An OBJ of two unit cubes, ``base`` under ``top``."""
    lines, offset = [], 0
    for name, z in (("base", 0.0), ("top", 1.0)):
        box = trimesh.creation.box(extents=(1, 1, 1))
        box.apply_translation((0.5, 0.5, z + 0.5))
        lines.append(f"o {name}")
        lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in box.vertices]
        lines += ["f " + " ".join(str(offset + 1 + i) for i in face) for face in box.faces]
        offset += len(box.vertices)
    path = tmp_path_factory.mktemp("tower") / "tower.obj"
    path.write_text("\n".join(lines) + "\n")
    return path


BAD_READS = {
    "no_support": {"support": None},
    "scene": {"support": "base", "scene": "dome"},
    "assembly": {"support": "base", "assembly": "x"},
    "support_int": {"support": [3]},
    "support_number": {"support": 3},
    "support_below_text": {"support_below": "a"},
    "support_below_nan": {"support_below": float("nan")},
    "support_below_bool": {"support_below": True},
    "ground_int": {"ground": 1},
    "mu_text": {"support": "base", "mu": "high"},
    "unknown": {"support": "base", "colour": 3},
    "point_load": {"support": "base", "point_loads": "top:1,2"},
}


@pytest.mark.parametrize("name", sorted(BAD_READS))
def test_bad_arguments_of_read(tower, name):
    with pytest.raises(MasonryError) as info:
        masonry.read(tower, **BAD_READS[name])
    assert len(str(info.value).splitlines()) == 1


@pytest.mark.parametrize("paths", [(), (3,), (None,), ("missing.obj",)])
def test_bad_paths_of_read(paths):
    with pytest.raises(MasonryError):
        masonry.read(*paths, ground=True)


def test_one_support_pattern_is_one_string_not_its_letters(tower):
    structure = masonry.read(tower, support="base")  # as ("base",), not "b", "a", ...
    assert list(structure.blocks.block_is_support) == [True, False]
    assert structure.source["supports"] == 1


BAD_BUILDS = [{"n": True}, {"n": 4.5}, {"n": "4"}, {"n": np.float64(4.5)},
              {"mu": np.nan}, {"mu": "0.7"}, {"scene": "moon"}, {"preset": "7"},
              {"colour": 1}, {"lateral": "east"}, {"crown_load": -1.0},
              {"friction_cone": "polygon:\u00b2"}, {"crown_load": 1e308}]


@pytest.mark.parametrize("inputs", BAD_BUILDS, ids=lambda d: "-".join(map(str, d)))
def test_bad_arguments_of_build(inputs):
    with pytest.raises(MasonryError) as info:
        masonry.build(**inputs)
    assert len(str(info.value).splitlines()) == 1


def test_numpy_numbers_are_numbers():
    plain = masonry.build(scene="arch", arch_blocks=5, arch_span=4.0, mu=0.7)
    numpy = masonry.build(scene="arch", arch_blocks=np.int64(5), arch_span=np.float32(4.0),
                          mu=np.float64(0.7))
    assert numpy.params == plain.params and numpy.id == plain.id
    assert type(numpy.params.geometry.arch_blocks) is int
    assert (~numpy.blocks.block_is_support).sum() == 5  # the voussoirs, beside 2 supports


def test_the_forces_of_an_infeasible_friction_net_solve():
    # a semicircular arch of t/R 0.04 is below Milankovitch's 0.1075: it cannot stand
    arch = masonry.build(scene="arch", arch_thickness=0.1, friction="net")
    assert arch.solve().verdict == "infeasible"
    with pytest.raises(MasonryError, match="friction='auto'"):
        arch.forces()


def test_bad_methods_arguments():
    arch = masonry.build(scene="arch", arch_blocks=5)
    for call in (lambda: arch.collapse(), lambda: arch.collapse(lateral="east"),
                 lambda: arch.collapse(colour=1), lambda: arch.stages(by="sideways"),
                 lambda: arch.export(colour=1)):
        with pytest.raises(MasonryError):
            call()


# ----------------------------------------------------------------------- read_table
@pytest.mark.parametrize("content", [b"", b"\n", b"\x00\x01\xff\xfe binary", b"PK\x03\x04",
                                     b"id,x_m\nseven,1.0\n", b"feasible\nmaybe\n"])
def test_read_table_of_what_is_no_table(tmp_path, content):
    path = tmp_path / "t.csv"
    path.write_bytes(content)
    with pytest.raises(MasonryError) as info:
        masonry.read_table(path)
    message = str(info.value)
    assert str(path) in message and len(message.splitlines()) == 1


def test_read_table_of_a_missing_file(tmp_path):
    with pytest.raises(MasonryError, match="missing.csv"):
        masonry.read_table(tmp_path / "missing.csv")


def test_a_nan_the_writer_prints_reads_back_as_nan(tmp_path):
    # forces.csv prints nan where an interface carries no normal force (no point of
    # application): a float column, a name column that holds "nan" stays text
    path = tmp_path / "forces.csv"
    path.write_bytes(_table([("id", np.arange(3)), ("name_a", np.array(["a", "nan", "c"])),
                             ("point_x_m", np.array([1.5, np.nan, -np.inf])),
                             ("eccentricity", np.array([np.nan, 0.25, 0.0]))]))
    assert "nan" in path.read_text()
    frame = masonry.read_table(path)
    assert frame["point_x_m"].dtype == np.float64 and frame["eccentricity"].dtype == float
    assert np.isnan(frame["point_x_m"][1]) and frame["point_x_m"][2] == -np.inf
    assert np.isnan(frame["eccentricity"][0]) and frame["eccentricity"][1] == 0.25
    assert list(frame["name_a"]) == ["a", "nan", "c"]


def test_a_stage_with_loose_blocks_reads_back_its_count(tmp_path):
    rows = [{c: None for c in STAGE_COLUMNS} | {"stage": 1, "laid": "b1", "bricks": 1,
                                                  "feasible": True, "loose": 0},
            {c: None for c in STAGE_COLUMNS} | {"stage": 2, "laid": "b2 b3", "bricks": 3,
                                                  "feasible": False, "loose": 2}]
    path = tmp_path / "stages.csv"
    path.write_bytes(stages_csv(rows))
    frame = masonry.read_table(path)
    assert list(frame["loose"]) == [0, 2] and str(frame["loose"].dtype) == "Int64"
    assert list(frame["feasible"]) == [True, False]
