"""Interface resultants (masonry.rbe.resultants): normal force, shear, point of
application and eccentricity, against sums by hand and limit states of statics."""

import numpy as np
import pytest
from test_rbe import MU, box, incline, make_interfaces, stack, vertex_forces

from masonry.interfaces import INTERFACE_KINDS, detect
from masonry.params import Params, validate
from masonry.scenes.arch import arch_radius
from masonry.rbe.equilibrium import VariableLayout
from masonry.rbe.resultants import interface_resultants
from masonry.rbe.solve import solve_rbe
from masonry.scenes.arch import build_arch

HORIZONTAL = INTERFACE_KINDS.index("horizontal")
RTOL = 1e-9


def square_and_tilted():
    """A unit square at z = 1 (normal +z) and a 0.4 x 0.2 rectangle tilted by 30 degrees."""
    square = box((0, 0, 1), (1, 1, 1))[[0, 1, 3, 2]]
    c, s = np.cos(np.pi / 6), np.sin(np.pi / 6)
    tilt = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    rectangle = box((0, 0, 0), (0.4, 0.2, 0))[[0, 1, 3, 2]] @ tilt.T + [2.0, 0.5, 0.3]
    return make_interfaces([(0, 1), (1, 2)], [square, rectangle],
                           [(0, 0, 1), tilt[:, 2]], [HORIZONTAL, HORIZONTAL])


def test_resultant_has_the_force_and_moment_of_the_vertex_forces():
    interfaces = square_and_tilted()
    layout = VariableLayout.from_interfaces(interfaces)
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 1e3, layout.n_columns)
    x[layout.columns("f1")] -= 500.0
    got = interface_resultants(interfaces, layout, x)
    force = vertex_forces(interfaces, layout, x)
    for k in range(len(interfaces)):
        rows = slice(interfaces.offsets[k], interfaces.offsets[k + 1])
        centre, n = interfaces.centre[k], interfaces.normal[k]
        total = force[rows].sum(axis=0)
        moment = sum(np.cross(p - centre, f)
                     for p, f in zip(interfaces.vertices[rows], force[rows]))
        sigma = (layout.component(x, "c")[rows] - layout.component(x, "t")[rows]).sum()
        assert got["sigma"][k] == pytest.approx(sigma, rel=RTOL)
        np.testing.assert_allclose(got["sigma"][k] * n + got["shear"][k], total,
                                   rtol=RTOL, atol=RTOL * np.abs(total).max())
        assert abs(got["shear"][k] @ n) <= RTOL * np.abs(total).max()
        # the point lies in the plane, and the resultant there plus the torsion about n
        # has the vertex forces' moment about the centre
        point = got["point"][k]
        assert abs((point - centre) @ n) <= RTOL
        reduced = np.cross(point - centre, total) + got["torsion"][k] * n
        np.testing.assert_allclose(reduced, moment, rtol=RTOL,
                                   atol=RTOL * np.abs(moment).max())


def test_centred_and_edge_loads_by_hand():
    interfaces = square_and_tilted()
    layout = VariableLayout.from_interfaces(interfaces)
    x = np.zeros(layout.n_columns)
    x[layout.columns("c")[:4]] = 250.0          # equal at the square's corners: centred
    x[layout.columns("c")[[4, 5]]] = [100, 300]  # the rectangle's first edge only
    got = interface_resultants(interfaces, layout, x)
    np.testing.assert_allclose(got["point"][0], [0.5, 0.5, 1.0], atol=1e-15)
    assert got["eccentricity"][0] == pytest.approx(0.0, abs=1e-15)
    vertices = interfaces.vertices[4:6]
    np.testing.assert_allclose(got["point"][1], (100 * vertices[0] + 300 * vertices[1]) / 400,
                               atol=1e-14)
    assert got["eccentricity"][1] == pytest.approx(1.0, rel=1e-12)


def test_no_normal_force_has_no_point():
    interfaces = square_and_tilted()
    layout = VariableLayout.from_interfaces(interfaces)
    x = np.zeros(layout.n_columns)
    x[layout.columns("c")[0]] = x[layout.columns("t")[2]] = 100.0  # a pure couple
    got = interface_resultants(interfaces, layout, x)
    assert np.isnan(got["point"][0]).all() and np.isnan(got["eccentricity"][0])
    np.testing.assert_allclose(got["torsion"][0], 0.0, atol=1e-12)
    # an unloaded interface has none either
    assert np.isnan(got["point"][1]).all() and np.isnan(got["eccentricity"][1])


def test_stacked_boxes_bear_under_their_centroids():
    blocks, interfaces = stack(3)
    result = solve_rbe(blocks, interfaces, mu=MU)
    got = interface_resultants(interfaces, result.layout, result.x)
    np.testing.assert_allclose(got["point"][:, :2], np.tile([0.2, 0.1], (3, 1)), atol=1e-9)
    assert np.abs(got["eccentricity"]).max() < 1e-7


@pytest.mark.parametrize("tan_theta", [0.2, 0.45])
def test_block_on_an_incline_bears_where_its_weight_line_meets_the_base(tan_theta):
    """The weight through the centroid meets the base h tan(theta) / 2 downhill of the
    centre: eccentricity h tan(theta) / b, 1 where the block tips."""
    base, height = 0.2, 0.4
    blocks, interfaces = incline(np.arctan(tan_theta), base, height)
    result = solve_rbe(blocks, interfaces, mu=MU)
    assert result.feasible
    got = interface_resultants(interfaces, result.layout, result.x)
    assert got["eccentricity"][0] == pytest.approx(height * tan_theta / base, rel=1e-6)
    assert got["sigma"][0] == pytest.approx(result.weight_N * np.cos(np.arctan(tan_theta)),
                                            rel=1e-6)


def test_arch_at_its_minimum_thickness_has_hinges():
    """16 voussoirs at 1.001 times the thrust line's minimum t/R (tests/test_arch.py): the
    only thrust line touches intrados and extrados, so some joints carry their resultant
    at the edge (eccentricity 1) and none beyond."""
    params = validate(Params.of(scene="arch", arch_blocks=16, mu=10.0))
    geometry = params.geometry
    radius, _ = arch_radius(geometry.arch_shape, geometry.arch_span, geometry.arch_rise)
    params = validate(params.replace(arch_thickness=1.001 * 0.1070762 * radius))
    scene = build_arch(params.geometry)
    interfaces = detect(scene.blocks, up=scene.block_up)
    result = solve_rbe(scene.blocks, interfaces, mu=params.analysis.mu, friction="net")
    assert result.feasible
    e = interface_resultants(interfaces, result.layout, result.x)["eccentricity"]
    assert e.max() <= 1 + 1e-6
    assert e.max() >= 0.99
    # a hinge at the crown or beside it and one at each haunch (symmetric pairs)
    assert (e > 0.98).sum() >= 3

