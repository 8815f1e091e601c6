"""Studies: leaves that call the pipeline many times and tabulate what comes out. The thesis's
structures (:mod:`.structures`), parameter sweeps (:mod:`.sweep`, their study files read
by :mod:`.study_file`, their workers :mod:`.workers`), optimisations (:mod:`.optimize`),
the arch's minimum thickness (:mod:`.thickness`) and its independent thrust line
(:mod:`.thrust_line`). Nothing in the pipeline imports them. Construction stages are
their own package (:mod:`masonry.stages`); the maintainers' benches live outside the
library (``benchmarks/``, installed as ``masonry_benchmarks``)."""
