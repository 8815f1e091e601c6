"""How the analyses use the machine's cores: the solvers' threads, and work on a second core.

The solvers (:mod:`masonry.rbe.solvers`) neither fork nor set threads (as scipy and cvxpy
leave parallelism to their callers); the analyses that call them decide here, from the
cores their own caller allows (``cores`` of :meth:`masonry.rbe.solve.RBEProblem.solve`
and :class:`masonry.rbe.collapse.CollapseLP`; default the process's,
:func:`masonry.forking.cores`):

- :func:`solver_threads`: BLAS on one thread, the block Cholesky factorizations on up to
  two (:func:`~masonry.rbe.solvers.cholesky.factor_threads`);
- :class:`Alongside`: the rigid block equilibrium's friction+ in a forked process while
  the load-path LP decides friction-net.

The collapse search's azimuths two at once (:func:`masonry.forking.two_at_once`) are
decided by :func:`masonry.rbe.lateral_search.worst_lateral`, the command line's one BLAS thread
for the whole process by :func:`masonry.forking.use_one_blas_thread`.
"""

import contextlib
import logging

from masonry import forking
from masonry.rbe.solvers.cholesky import factor_threads

log = logging.getLogger(__name__)


@contextlib.contextmanager
def solver_threads(cores=None):
    """The threads the solvers run on, as their caller decides: BLAS on one
    (:func:`masonry.forking.one_blas_thread`: a factorization makes thousands of small
    BLAS calls) and the block Cholesky factorizations on up to two, at most ``cores``
    (:func:`masonry.forking.usable_cores`)."""
    with forking.one_blas_thread(), factor_threads(forking.usable_cores(cores)):
        yield


class Alongside:
    """friction+ solved in a forked copy of this process, on the second core, while the
    load-path LP decides friction-net in this one: started when Newton hands friction-net
    over to the LP (it has neither solved nor certified it: most such structures are
    infeasible), taken when friction-net has no solution, ended unused when it has one.
    Both factor on one thread from the start, the forked one to its end (two threads
    gain little at the sizes measured: docs/bench.md, "Batched leaves"). The forked
    process solves friction+ as this one would after friction-net (the same candidates
    from the same state), so the result does not depend on where it was solved; if it
    cannot start or fails, this process solves friction+ (with a warning).

    Parameters
    ----------
    solve_plus : callable
        ``solve_plus(attempts)``: friction+ as this process would solve it, its attempts
        appended to the list ``attempts``; called in the forked process.
    """

    def __init__(self, solve_plus):
        self.solve_plus = solve_plus
        self.forked = forking.Forked([self._solve])
        self.threads = contextlib.ExitStack()

    @staticmethod
    def wanted(friction, solver, preset, cores) -> bool:
        """Whether a solve may work on the second core: the thesis's flow with friction+
        on the Newton system (not Clarabel's), a process that may fork, two ``cores``
        allowed."""
        return (friction == "auto" and solver is None and preset.plus_solver == "interior"
                and cores >= 2 and forking.can_fork())

    @property
    def started(self) -> bool:
        return self.forked.started

    def start(self):
        """Start friction+ on the second core (once)."""
        if self.started:
            return
        log.info("friction+ starts on the second core while the load-path LP decides "
                 "friction-net")
        self.threads.enter_context(factor_threads(1))
        try:
            self.forked.start()
        except OSError as error:  # no memory or processes left for a fork
            log.warning("friction+ cannot start on the second core (%s); it is solved "
                        "here after friction-net", error)
            self.close()

    def _solve(self):
        """In the forked process: friction+ and its attempts."""
        logging.disable(logging.INFO)  # its progress would mix with this process's
        attempts = []
        return self.solve_plus(attempts), attempts

    def solved(self, attempts):
        """friction+ from the second core, its attempts appended to ``attempts``; None
        if it failed (this process then solves it)."""
        try:
            solved, theirs = self.forked.result()
        except Exception as error:
            log.warning("friction+ on the second core failed (%s); solving it here", error)
            self.close()
            return None
        log.info("friction+ was solved on the second core")
        attempts.extend(theirs)
        return solved

    def close(self):
        """End the forked process (if it still runs) and give the factorizations their
        threads back."""
        try:
            self.forked.close(cancel=True)
        finally:
            self.threads.close()
