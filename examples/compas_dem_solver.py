"""masonry as the solver of a compas_dem Problem (docs/assemblies.md, "masonry as a
compas_dem solver"): an arch built with compas_dem's own template, supports and friction
set the compas_dem way, solved by masonry, and its forces read back from compas_dem's
Results.

    pip install "masonry[compas]"
    python examples/compas_dem_solver.py
"""

from compas_dem.models import BlockModel
from compas_dem.problem import Problem
from compas_dem.templates import ArchTemplate
from compas_dem.material import Stone

from masonry.interop.compas_dem import solve


def arch_problem() -> Problem:
    """A semicircular arch of compas_dem's template, its two springer blocks fixed."""
    model = BlockModel.from_template(ArchTemplate(rise=3.0, span=10.0, thickness=0.5,
                                                  depth=0.5, n=20))
    stone = Stone(density=2000)
    model.add_material(stone)
    blocks = sorted(model.elements(), key=lambda block: block.point[0])
    for block in model.elements():
        model.assign_material(stone, element=block)
    blocks[0].is_support = blocks[-1].is_support = True
    problem = Problem(model)
    problem.set_contact_model("MohrCoulomb", mu=0.6)
    problem.add_boundary_condition("self weight")
    return problem


def main():
    problem = arch_problem()
    results = solve(problem)
    print(f"masonry: {results.metadata['verdict']} under self weight "
          f"({results.metadata['weight_N']:.0f} N, mu {results.metadata['mu']})")
    for edge in list(results.edges())[:3]:
        fx, fy, fz = results.resultant_global(edge)
        print(f"joint {edge}: normal {sum(results.force_normal(edge)):.0f} N, "
              f"force ({fx:.0f}, {fy:.0f}, {fz:.0f}) N")
    return results


if __name__ == "__main__":
    main()
