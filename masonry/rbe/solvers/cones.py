"""The cones of the own interior point methods, one small cone per interface vertex.

The methods (:mod:`.interior`, :mod:`.interior_lp`) are primal-dual path-following with
Nesterov-Todd scaling in the form of CVXOPT's cone solvers (L. Vandenberghe, "The CVXOPT
linear and quadratic cone program solvers", 2010): for a primal point ``u`` and a dual
point ``z`` of a cone, a symmetric positive definite scaling ``W`` with ::

    W^-1 u = W z = lam

turns the complementarity ``u o z = 0`` (the cone's Jordan product) into ``lam o lam``,
and a Newton step's complementarity row into ``lam o (W^-1 du + W dz) = -r``. Eliminated,
it leaves ``W^2`` in the normal equations, one small block per vertex: the orthant's is
diagonal (``u / z``), the second-order cone's a dense 3 x 3 block, so both keep the
normal matrix's pattern of six rows per free block.

- :class:`Orthant`: ``m`` nonnegative numbers per vertex (a pyramid's edge ray weights,
  its face slacks, a tension ``t >= 0``).
- :class:`Lorentz`: the second-order cone ``u0 >= ||(u1, ..., u_m-1)||`` per vertex
  (Coulomb's friction cone after scaling ``c`` by ``mu``, ``m = 3``; a support force and
  its bound, ``m = 4``).

Every array is ``(V, m)``: one row per vertex. The degree of a vertex (the number of
complementarity pairs the gap ``u . z`` is divided by) is ``m`` for the orthant and 1 for
a second-order cone, as in CVXOPT.
"""

import numpy as np


def _step_to_one(worst) -> float:
    """The largest step ``<= 1`` along a direction whose worst ``1 / step`` over the
    cone's entries is ``worst`` ((V,) float; <= 0 where the direction stays inside)."""
    most = float(worst.max(initial=0.0))
    return 1.0 if most <= 1.0 else 1.0 / most


class Orthant:
    """``m`` nonnegative entries per vertex."""

    def __init__(self, m: int):
        self.m = m
        self.degree = m

    def identity(self, count) -> np.ndarray:
        return np.ones((count, self.m))

    def min_eigenvalue(self, u) -> np.ndarray:
        """(V,) float: per vertex, the least entry (negative: outside the cone)."""
        return u.min(axis=1)

    def trace(self, u) -> float:
        """``e . u``."""
        return float(u.sum())

    def max_step(self, u, du) -> float:
        """Largest ``a <= 1`` with ``u + a du`` in the cone (``u`` inside)."""
        return _step_to_one(-(du / u))

    def scaling(self, u, z) -> "OrthantScaling":
        return OrthantScaling(u, z)

    @staticmethod
    def product(a, b) -> np.ndarray:
        return a * b

    @staticmethod
    def divide(lam, r) -> np.ndarray:
        """``x`` with ``lam o x = r``."""
        return r / lam


class OrthantScaling:
    """The orthant's scaling: ``W = diag(sqrt(u / z))``, ``lam = sqrt(u z)``."""

    def __init__(self, u, z):
        self.d = u / z
        self.w = np.sqrt(self.d)
        self.lam = np.sqrt(u * z)

    def times_w(self, v):
        return self.w * v

    def times_w_inverse(self, v):
        return v / self.w

    def times_w2(self, v):
        return self.d * v


class Lorentz:
    """The second-order cone ``u0 >= ||(u1, ..., u_m-1)||``, one per vertex (``m = 3``
    unless given)."""

    degree = 1

    def __init__(self, m: int = 3):
        self.m = m

    def identity(self, count) -> np.ndarray:
        e = np.zeros((count, self.m))
        e[:, 0] = 1.0
        return e

    @staticmethod
    def min_eigenvalue(u) -> np.ndarray:
        """(V,) float: ``u0 - ||u1||``, the smaller eigenvalue of the Jordan algebra."""
        return u[:, 0] - _norm(u[:, 1:])

    @staticmethod
    def trace(u) -> float:
        """``e . u`` with ``e = (1, 0, ...)``."""
        return float(u[:, 0].sum())

    @staticmethod
    def max_step(u, du) -> float:
        """Largest ``a <= 1`` with ``u + a du`` in the cone (``u`` inside): in the frame
        of the Lorentz boost that takes ``u`` to ``nu e`` (``nu^2 = u^T J u``), the
        direction is ``rho``, and ``e + a rho`` leaves the cone at ``a = 1 / (||rho1|| -
        rho0)`` (ECOS's line search, Domahidi et al. 2013)."""
        nu = _jnorm(u)
        unit = u / nu[:, None]
        rho0 = (unit[:, 0] * du[:, 0] - np.einsum("vi,vi->v", unit[:, 1:], du[:, 1:])) / nu
        rho1 = (du[:, 1:] / nu[:, None]
                - ((rho0 + du[:, 0] / nu) / (unit[:, 0] + 1.0))[:, None] * unit[:, 1:])
        return _step_to_one(_norm(rho1) - rho0)

    @staticmethod
    def scaling(u, z) -> "LorentzScaling":
        return LorentzScaling(u, z)

    @staticmethod
    def product(a, b) -> np.ndarray:
        """The Jordan product ``(a . b, a0 b1 + b0 a1)``."""
        out = np.empty_like(a)
        out[:, 0] = np.einsum("vi,vi->v", a, b)
        out[:, 1:] = a[:, :1] * b[:, 1:] + b[:, :1] * a[:, 1:]
        return out

    @staticmethod
    def divide(lam, r) -> np.ndarray:
        """``x`` with ``lam o x = r``: ``x0 = (lam0 r0 - lam1 . r1) / det(lam)``,
        ``x1 = (r1 - x0 lam1) / lam0``."""
        det = _jnorm(lam) ** 2
        out = np.empty_like(r)
        out[:, 0] = (lam[:, 0] * r[:, 0] - np.einsum("vi,vi->v", lam[:, 1:], r[:, 1:])) / det
        out[:, 1:] = (r[:, 1:] - out[:, :1] * lam[:, 1:]) / lam[:, :1]
        return out


def _norm(u) -> np.ndarray:
    """(V,) float: the rows' Euclidean norms (``hypot`` for two columns, the friction
    cone's, which is faster)."""
    if u.shape[1] == 2:
        return np.hypot(u[:, 0], u[:, 1])
    return np.sqrt(np.einsum("vi,vi->v", u, u))


def _jnorm(u) -> np.ndarray:
    """(V,) float: ``sqrt(u0^2 - ||u1||^2)`` without the cancellation of the squares."""
    radius = _norm(u[:, 1:])
    return np.sqrt(np.maximum((u[:, 0] - radius) * (u[:, 0] + radius), 0.0))


class LorentzScaling:
    """The Nesterov-Todd scaling of a pair ``(u, z)`` inside the second-order cone.

    With ``u_ = u / sqrt(u^T J u)``, ``z_ = z / sqrt(z^T J z)`` (``J = diag(1, -1, ...)``),
    ``gamma = sqrt((1 + u_ . z_) / 2)`` and the scaling point ``w = (u_ + J z_) / (2
    gamma)`` (``w^T J w = 1``), ``W = beta (2 v v^T - J)`` with ``v = (w + e) /
    sqrt(2 (w0 + 1))`` and ``beta = (u^T J u / z^T J z)^(1/4)``; then ``W^-1 = (2 J v
    v^T J - J) / beta`` and ``W z = W^-1 u`` (Vandenberghe 2010, section 4.3, with the
    roles of the primal and dual points as here: ``u = W^2 z``).
    """

    def __init__(self, u, z):
        nu_u, nu_z = _jnorm(u), _jnorm(z)
        u_, z_ = u / nu_u[:, None], z / nu_z[:, None]
        gamma = np.sqrt(0.5 * (1.0 + np.einsum("vi,vi->v", u_, z_)))
        signs = np.ones(u.shape[1])
        signs[1:] = -1.0
        jz = z_ * signs
        w = (u_ + jz) / (2.0 * gamma[:, None])
        v = w.copy()
        v[:, 0] += 1.0
        v /= np.sqrt(2.0 * (w[:, 0] + 1.0))[:, None]
        beta = np.sqrt(nu_u / nu_z)
        J = np.diag(signs)
        outer = v[:, :, None] * v[:, None, :]
        self.W = beta[:, None, None] * (2.0 * outer - J)
        jv = v * signs
        self.W_inverse = (2.0 * jv[:, :, None] * jv[:, None, :] - J) / beta[:, None, None]
        self.D = self.W @ self.W
        self.lam = np.einsum("vij,vj->vi", self.W, z)

    def times_w(self, x):
        return np.einsum("vij,vj->vi", self.W, x)

    def times_w_inverse(self, x):
        return np.einsum("vij,vj->vi", self.W_inverse, x)

    def times_w2(self, x):
        return np.einsum("vij,vj->vi", self.D, x)


def centred_start(cones, u, z):
    """Mehrotra's starting point from least-squares primal and dual points ``u``, ``z``
    (lists of (V, m) arrays, one per cone of ``cones``): both shifted inside their cones
    by 1.5 times their most negative eigenvalue over all cones, then along the cones'
    identity ``e`` by half of their complementarity over the other's trace."""
    e = [cone.identity(len(a)) for cone, a in zip(cones, u)]

    def inside(points):
        least = min(float(cone.min_eigenvalue(a).min()) for cone, a in zip(cones, points))
        return [a + max(0.0, -1.5 * least) * unit for a, unit in zip(points, e)]

    def trace(points):
        return max(sum(cone.trace(a) for cone, a in zip(cones, points)),
                   np.finfo(float).tiny)

    u, z = inside(u), inside(z)
    product = sum(float(a.ravel() @ b.ravel()) for a, b in zip(u, z))
    # both are zero only if u = 0 solves the problem (b = 0)
    shift = 0.5 * product / trace(z) + np.finfo(float).eps
    u = [a + shift * unit for a, unit in zip(u, e)]
    shift = 0.5 * product / trace(u) + np.finfo(float).eps
    z = [a + shift * unit for a, unit in zip(z, e)]
    return u, z
