"""Rigid block equilibrium (docs/model.md 6): the analysis model of a scene with its boundary
(:mod:`.boundary`), the scaled matrices (:mod:`.equilibrium`), the QP and its friction flow
(:mod:`.solve`) on the solver back ends (:mod:`.solvers`)."""
