"""Studies: leaves that call the pipeline many times and tabulate what comes out. The thesis's
structures (:mod:`.structures`), parameter sweeps (:mod:`.sweep`), the solver benchmark
(:mod:`.bench`), the arch's minimum thickness (:mod:`.thickness`) and its independent
thrust line (:mod:`.thrust_line`). Nothing in the pipeline imports them."""
