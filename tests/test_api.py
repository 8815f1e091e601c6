"""The Python interface: what a notebook reads agrees with statics and with the files
``masonry run`` writes."""

import numpy as np
import pandas
import pytest

import masonry
from masonry.errors import MasonryError, ParameterError
from masonry.rbe.solve import ACCURACY

ARCH = {"scene": "arch", "arch_thickness": 1.0, "plots": False}


@pytest.fixture(scope="module")
def arch():
    return masonry.build(**ARCH)


def test_the_supports_carry_the_weight(arch):
    """Statics, independent of the solver: the forces the supports give to the blocks
    they touch add up to the weight of the free blocks, and point up."""
    result = arch.solve()
    assert result.verdict == "feasible" and result.moi_factor == 0
    forces = arch.forces()
    on_support = arch.blocks.block_is_support[forces["block_a"].to_numpy()]
    frame = np.stack([forces[[f"{axis}_{k}" for k in "xyz"]].to_numpy()
                      for axis in ("normal", "t1", "t2")])
    push = (-forces["normal_N"].to_numpy()[:, None] * frame[0]
            + forces["t1_N"].to_numpy()[:, None] * frame[1]
            + forces["t2_N"].to_numpy()[:, None] * frame[2])[on_support].sum(axis=0)
    tolerance = ACCURACY["balanced"].residual * result.weight_N
    np.testing.assert_allclose(push, [0.0, 0.0, result.weight_N], atol=tolerance)


def test_the_forces_are_the_rows_of_forces_csv(arch, tmp_path):
    record = arch.export(tmp_path, printable=False)
    written = pandas.read_csv(f"{record['path']}/RBE/forces.csv", index_col="id")
    forces = arch.forces()
    assert list(written.columns) == list(forces.columns)
    assert len(written) == len(forces) == len(arch.interfaces)
    numbers = forces.select_dtypes("number").columns
    # the CSV prints 12 significant digits; forces near zero to the weight's
    np.testing.assert_allclose(written[numbers].to_numpy(float), forces[numbers].to_numpy(float),
                               rtol=1e-9, atol=1e-9 * arch.solve().weight_N)


def test_collapse_and_stages_answer_as_the_command_line(arch, tmp_path):
    """The lateral factor of the arch is the one ``masonry run --lateral 0`` records, and
    its stages laid in pairs from the springings stand where the statics of the half
    arches says (tests/test_stages.py): stages 1-2 and the closed arch."""
    collapse = arch.collapse(lateral=0)
    record = masonry.build(**ARCH, lateral=0).export(tmp_path, printable=False)
    assert collapse.load_factor == pytest.approx(record["collapse"]["load_factor"], rel=1e-9)
    stages = masonry.build(scene="arch").stages(by="block", order="z")
    assert stages["feasible"].tolist() == [True, True] + [False] * 5 + [True]
    assert stages["bricks"].tolist() == list(range(2, 17, 2))
    # the least adhesion of each stage: 0 where it stands dry, and as much as the
    # structure-level a* of the stage's own model (tests/test_stage_adhesion.py)
    adhesion = stages["adhesion_kPa"]
    assert adhesion[stages["feasible"]].tolist() == [0.0, 0.0, 0.0]
    assert (adhesion[~stages["feasible"]] > 0).all()


def test_a_read_assembly_is_analysed_like_masonry_analyze(fixtures_dir):
    arch = masonry.read(fixtures_dir / "assembly" / "arch_rhino.obj", support=["pier_*"])
    assert arch.source["supports"] == 2 and arch.id.startswith("assembly_arch_rhino_")
    assert arch.solve().verdict == "feasible"  # t/R = 0.2, twice the minimum


def test_bad_inputs_are_refused_by_name():
    with pytest.raises(ParameterError, match="mu"):
        masonry.build(mu=-1)
    with pytest.raises(ParameterError, match="preset"):
        masonry.build(preset="9")
    with pytest.raises(ParameterError, match="load"):
        masonry.build(scene="arch").collapse()
    with pytest.raises(ParameterError, match="colour"):
        masonry.build(scene="arch").export(colour="red")
    with pytest.raises(MasonryError, match="no support"):
        masonry.read(__file__.replace("test_api.py", "../fixtures/assembly/arch_rhino.obj"))
