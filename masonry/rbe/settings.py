"""The analysis of a run, declared (:mod:`masonry.parameters`): the material, the friction
law and model, the boundary of a section, and the solvers' accuracy."""

from dataclasses import dataclass

import numpy as np

from masonry.contact import TENSION_RATIO, ContactLaw, joint_factor
from masonry.errors import ParameterError
from masonry.friction import FrictionCone, FrictionModelError
from masonry.parameters import check_fields, declare
from masonry.rbe.accuracy import ACCURACY
from masonry.rbe.solvers import BACKENDS, RBE, names

FRICTIONS = ("net", "plus", "auto")
FRICTION_LAWS = ("associated", "non-associative")
BOUNDARIES = ("free", "rigid", "cyclic")


@dataclass(frozen=True)
class Analysis:
    """How a run's structure is analysed (docs/model.md 6).

    ``mu`` the friction coefficient, ``density`` kg/m^3, ``friction`` the thesis's flow
    (net | plus | auto), ``friction_cone`` the friction model (:mod:`masonry.friction`;
    None: the accuracy preset's, an isotropic one), ``accuracy`` the solver preset
    (:data:`masonry.rbe.solve.ACCURACY`), ``solver`` a solver in place of the preset's,
    ``boundary`` what a section's end bricks bear on (free, rigid, cyclic; other scenes
    are free), ``friction_law`` of the collapse load factor (associated: the cone
    program; non-associative: joints that slide without dilating, an estimate),
    ``cohesion_kpa`` and ``tensile_kpa`` the mortar's cohesion and tensile strength at
    every joint (kPa; 0: dry joints; :mod:`masonry.contact`),
    ``head_joint_ratio`` and ``support_joint_ratio`` the strength of head joints and of
    joints with a support as a fraction of the bed joints' (cohesion and tension alike,
    also of a mortar by age and of the least adhesion;
    :func:`masonry.contact.joint_factor`),
    ``adhesion_tension_ratio`` the ratio ``t_c / c`` of the least adhesion
    (:mod:`masonry.rbe.adhesion`).
    """

    mu: float = declare(0.7, "friction coefficient", low=0.01, high=10.0, tag="mu",
                        expected="0.01 to 10 (friction coefficients of masonry are 0.3 "
                                 "to 1; beyond these ends the friction cones are flat or "
                                 "closed to the solvers' precision)")
    density: float = declare(2000.0, "kg/m^3", low=1.0, high=1e7, tag="rho",
                             expected="1 to 1e+07 (kg/m^3: forces scale with it exactly; "
                                      "masonry is 1500 to 3000)")
    friction: str = declare("auto", "net | plus | auto (net, then plus if infeasible)",
                            kind="str", choices=FRICTIONS,
                            help="net, plus, or auto (net, then plus if infeasible; "
                                 "default)")
    friction_cone: str | None = declare(
        None, "the friction model", kind="any", optional=True, tag="cone",
        metavar="circle|polygon:K|square",
        help="friction model: circle (Coulomb's isotropic cone, exact; the default), "
             "polygon:K (the inscribed K-sided pyramid, 8 <= K <= 256: safe, within "
             "1 - cos(pi/K) of Coulomb; for linear solvers) or square (the thesis's "
             "pyramid |f1|, |f2| <= mu c: up to 41 % more friction than Coulomb, "
             "direction dependent; to reproduce the thesis only)")
    accuracy: str = declare(
        "balanced", "solver preset", kind="str", choices=tuple(ACCURACY), tag="",
        help="solver preset: fast, balanced (default; fast with --fast) or accurate "
             "(interior point, tight tolerances, LP check); see 'masonry bench'")
    solver: str | None = declare(
        None, "a solver in place of the preset's", kind="str", choices=names(RBE),
        optional=True, tag="",
        help="override the preset's QP solver: newton (semismooth Newton, friction-net), "
             "interior (own primal-dual interior point, friction+), clarabel (interior "
             "point), osqp (ADMM), or clarabel-cvxpy / osqp-cvxpy (through cvxpy, the "
             "reference)")
    boundary: str = declare(
        "free", "what the section's end bricks bear on", kind="str", choices=BOUNDARIES,
        tag="b", names_geometry=True,
        help="what a section's end bricks bear on: cyclic (its neighbours by exact "
             "rotational symmetry: the whole dome; the default), free (nothing: the web "
             "alone) or rigid (immovable neighbouring webs)")
    friction_law: str = declare(
        "associated", "of the collapse load factor", kind="str", choices=FRICTION_LAWS,
        help="associated (default: the LP; sliding joints dilate, which can overestimate "
             "the factor) or non-associative (an estimate with joints that slide without "
             "dilating: friction capacities fixed from the last collapse and solved "
             "again)")
    cohesion_kpa: float = declare(
        0.0, "kPa, the mortar's cohesion at every joint", low=0.0, high=1e6, tag="coh",
        expected="0 to 1e+06 (kPa: fresh mortar 0.1 to a few, hardened lime mortar 100 "
                 "to 300)", metavar="KPA",
        help="the mortar's cohesion at every joint, kPa (|f| <= mu n + c A at a vertex of "
             "tributary area A; default 0: dry joints)")
    tensile_kpa: float = declare(
        0.0, "kPa, the mortar's tensile strength at every joint", low=0.0, high=1e6,
        tag="ten", expected="0 to 1e+06 (kPa; cut off at cohesion/mu)", metavar="KPA",
        help="the mortar's tensile strength at every joint, kPa (n >= -t A; cut off at "
             "cohesion/mu; default 0)")
    head_joint_ratio: float = declare(
        1.0, "head joints' strength over the bed joints'", low=0.0, high=1.0, tag="hj",
        expected="0 to 1 (a fraction of the bed joints' cohesion and tensile strength; "
                 "EN 1996-1-1 halves the shear strength of unfilled perpends)",
        metavar="R", help="head joints hold R times the bed joints' cohesion and tensile "
                          "strength (0 to 1; default 1; a joint between two webs is a "
                          "head joint)")
    support_joint_ratio: float = declare(
        1.0, "the strength of joints with a support over the bed joints'", low=0.0,
        high=1e6, tag="sj", expected="0 to 1e+06 (a factor on the bed joints' cohesion "
                                     "and tensile strength; 0: dry on its supports)",
        metavar="R", help="joints with a support hold R times the bed joints' strengths "
                          "(default 1; 0: dry on the supports)")
    adhesion_tension_ratio: float = declare(
        TENSION_RATIO, "t_c / c of the least adhesion", low=0.0, high=100.0, tag="atr",
        expected="0 to 100 (the least adhesion's tensile strength over its cohesion; "
                 "0.5 by default, 0: no tension)", metavar="R",
        help="t_c / c of the least adhesion a structure needs (c = a, t_c = R a; 0 to "
             "100; default 0.5, 0: no tension)")

    def checked(self) -> "Analysis":
        """This analysis validated, the friction model in its canonical spelling; raises
        :class:`~masonry.errors.ParameterError`."""
        check_fields(self)
        try:
            cone = self.cone
        except FrictionModelError as error:
            raise ParameterError("friction_cone", self.friction_cone, str(error)) from None
        if self.solver is not None and not BACKENDS[self.solver].states(cone):
            if self.friction_cone is None:
                raise ParameterError("solver", self.solver, f"a solver of Coulomb's cone "
                                     f"(the default friction model): "
                                     f"{', '.join(names(RBE, cone))}; or a pyramid: "
                                     f"--friction-cone polygon:16")
            raise ParameterError("friction_cone", self.friction_cone, f"a pyramid (polygon:K "
                                 f"or square) with --solver {self.solver}, which takes "
                                 f"linear constraints only", related=("solver",))
        if self.friction_cone is None:
            return self
        return Analysis(**{**self.__dict__, "friction_cone": cone.name})

    @property
    def law(self) -> ContactLaw:
        """The contact law every analysis of the run asks (:mod:`masonry.contact`), at
        its bed joints; :meth:`law_on` gives every joint's."""
        return ContactLaw(self.cone, self.mu, 1e3 * self.cohesion_kpa, 1e3 * self.tensile_kpa)

    def joint_factor(self, interfaces) -> float | np.ndarray:
        """Every vertex's strength over the bed joints' (1.0, a float, where every joint
        has the bed joints'; :func:`masonry.contact.joint_factor`)."""
        return joint_factor(interfaces, self.head_joint_ratio, self.support_joint_ratio)

    def law_on(self, interfaces) -> ContactLaw:
        """The contact law of every joint of ``interfaces``: :attr:`law` scaled by
        :meth:`joint_factor` (per vertex where the joint kinds differ)."""
        return self.law.scaled(self.joint_factor(interfaces))

    def law_text(self) -> str:
        """The contact law in one line, with the joint kinds' ratios where they are not
        1 and the joints have a mortar."""
        text = self.law.describe()
        return text if self.law.is_dry else text + self.kinds_text()

    def kinds_text(self) -> str:
        """The joint kinds' ratios as the end of a law's line (``' at bed joints; head
        joints x0.5, joints with a support x1'``), '' where both are 1."""
        if (self.head_joint_ratio, self.support_joint_ratio) == (1, 1):
            return ""
        return (f" at bed joints; head joints x{self.head_joint_ratio:g}, joints with a "
                f"support x{self.support_joint_ratio:g}")

    @property
    def cone(self) -> FrictionCone:
        """The friction model: :attr:`friction_cone`, else the accuracy preset's."""
        return FrictionCone.parse(ACCURACY[self.accuracy].cone if self.friction_cone is None
                                  else self.friction_cone)

    # the analyses' keyword arguments, unpacked here once for every caller
    def rbe_options(self) -> dict:
        """The keyword arguments of the rigid block equilibrium
        (:meth:`masonry.rbe.solve.RBEProblem.solve`,
        :meth:`masonry.rbe.sequence.StageSequence.solve`): ``mu``, ``density``,
        ``friction``, ``solver``, ``accuracy`` and ``cone`` (:attr:`friction_cone`: None
        leaves the preset's), without the mortar (:meth:`mortar_on`)."""
        return dict(mu=self.mu, density=self.density, friction=self.friction,
                    solver=self.solver, accuracy=self.accuracy, cone=self.friction_cone)

    def material_options(self) -> dict:
        """``mu``, ``density`` and ``cone`` (:attr:`cone`): the keyword arguments the
        centering force, the collapse load factor and the least adhesion share."""
        return dict(mu=self.mu, density=self.density, cone=self.cone)

    def adhesion_options(self) -> dict:
        """The keyword arguments of the least adhesion
        (:func:`masonry.rbe.adhesion.least_adhesion`,
        :meth:`masonry.rbe.sequence.StageSequence.adhesion`): :meth:`material_options`,
        the tension ratio and the joint kinds' ratios."""
        return dict(**self.material_options(), ratio=self.adhesion_tension_ratio,
                    head_ratio=self.head_joint_ratio, support_ratio=self.support_joint_ratio)

    def mortar_on(self, interfaces) -> dict:
        """The mortar at ``interfaces`` as the analyses' keyword arguments: ``cohesion``
        and ``tensile``, pascals, numbers or per vertex where the joint kinds differ
        (:meth:`law_on`)."""
        law = self.law_on(interfaces)
        return dict(cohesion=law.cohesion_Pa, tensile=law.tensile_Pa)
