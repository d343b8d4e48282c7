"""Which term of a user's lumped model is wrong: a diagnosis by one-term changes of the reference.

A user's lumped gear-train model that disagrees with the reference (Lin & Parker 1999; Kiracofe & Parker
2007 for several stages) usually differs in one term.  Every candidate here is the reference changed in
one term, its modes computed exactly (an eigenproblem per candidate, not first-order sensitivities) and
scored against what is known of the suspect model (:class:`Evidence`):

* a deflection row (a bearing, support, coupling or shaft row; a mesh's line-of-action row, named by its
  mesh id) with one coefficient dropped ("dropped coupling") or its sign flipped ("sign error");
* a row's stiffness times a fitted factor ("stiffness");
* a member's mass on its two transverse translations, its rotational inertia or its axial mass times a
  fitted factor ("inertia": the member's entries of M);
* the Coriolis matrix dropped ("gyroscopic") or the centripetal stiffness dropped ("centripetal"), seen only
  in the frequencies at speed, where the degenerate pairs split (Cooley & Parker 2012);
* when the evidence lacks coordinates: the reference with them held ("held coordinates"); then every other
  candidate is a one-term change of that held reference.

The score of a candidate is the rms relative frequency error at rest (modes compared in sorted order, each
error |f - f_e| / max(f, f_e), so a rigid mode that should not be one counts 1), plus the mean of 1 - the
paired modal assurance when shapes are given (the mass-weighted MAC of Allemang & Brown 1982, summed over a
multiple frequency's modes as in :mod:`gearcheck.compare.engine.mode_pairing`), plus the rms relative frequency
error at speed when those are given.  Shapes are what tell planet 1 from planet 2: frequencies do not change
when the planets are relabelled, so candidates the evidence cannot tell apart (same frequencies, same score)
are reported as one class with their equivalents.

Fitted factors are fitted to the at-rest frequencies, on log factor within :data:`FACTOR_BOUNDS`: a coarse
grid, then Gauss-Newton steps with the eigenvalue derivatives (Fox & Kapoor 1968).  Every candidate's modes at
rest are solved in batches (the reference's K and M are whitened once by the Cholesky factor of M); the
gyroscopic eigenproblem at speed is solved only for the candidates whose at-rest score could still place
them among the best (branch and bound: the at-speed part of a score is never negative).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla

from gearcheck.lumped.assembly import LumpedModel
from gearcheck.lumped.constraints import constrained
from gearcheck.train.spec import AXIAL
from gearcheck.lumped.modal import modes, modes_at_speed
from gearcheck.shared.errors import GearcheckError, UnsupportedError
from gearcheck.shared.modal import DEGENERACY_TOLERANCE, RIGID_TOLERANCE, STABILITY_TOLERANCE

KINDS = ("no mistake", "held coordinates", "dropped coupling", "sign error", "stiffness", "inertia", "gyroscopic",
         "centripetal")
AGREEMENT = 1e-9  # a score below it is round-off: the candidate explains the evidence
FACTOR_BOUNDS = (1e-3, 1e3)  # fitted factors: wide enough for a unit slip (mm for m, g for kg)
COEFFICIENT_FLOOR = 1e-12  # a row coefficient below this times the row's largest is a zero (cos(pi/2))
FACTOR_RESOLUTION = 1e-6  # a fitted factor closer to 1 is no change (the reference itself)
EQUIVALENCE = 1e-7  # candidates whose frequencies agree to this (relative) and whose scores agree look alike
GRID = np.log(np.geomspace(*FACTOR_BOUNDS, 7))  # start of the fits: factors 1e-3, 1e-2, ..., 1e3
NEWTON_STEPS = 30
MAX_STEP = 2.0  # largest Gauss-Newton step in log factor
BATCH = 256  # candidates scored together (memory)


@dataclass
class Evidence:
    """What is known of the suspect model, in the reference's physical coordinates.

    ``labels``: its coordinates, a subset of the reference's ``dofs.labels()`` (all of them for a full model);
    ``frequencies``: Hz at rest, ascending (rigid modes 0), the lowest ones or all; ``shapes``: (len(labels),
    len(frequencies)) real shapes at rest, or None; ``mass``: its mass matrix over ``labels`` (weights the
    MAC), or None (then the candidate's own mass weights it); ``frequencies_at_speed``: Hz of its gyroscopic
    modes at the reference's operating speed, ascending, or None."""

    labels: list[str]
    frequencies: np.ndarray
    shapes: np.ndarray | None = None
    mass: np.ndarray | None = None
    frequencies_at_speed: np.ndarray | None = None

    @classmethod
    def of_model(cls, model: LumpedModel, shapes: bool = True, at_speed: bool = True) -> Evidence:
        """The evidence a lumped model (a user's, in the reference's coordinates) gives: its modes at rest and,
        with ``at_speed``, its gyroscopic frequencies at its operating speed."""
        rest = modes(model)
        speed = modes_at_speed(model, model.spec.operating.input_speed).frequencies if at_speed else None
        return cls(model.dofs.labels(), rest.frequencies, rest.shapes if shapes else None,
                   model.M.copy() if shapes else None, speed)


@dataclass
class Candidate:
    """One term of the reference changed, and how well the changed reference explains the evidence.

    ``row``: the row it changes (a mesh by its mesh id); ``coordinate``: the coefficient's coordinate;
    ``member`` and ``coordinates``: the member whose inertia it scales and the coordinates it scales it on
    (or the coordinates held); ``factor``: the fitted factor; ``parts``: the score's terms (rest, shapes,
    speed); ``equivalents``: the other candidates this evidence cannot tell from this one."""

    term: str
    kind: str
    score: float = math.nan
    parts: dict[str, float] = field(default_factory=dict)
    row: str | None = None
    coordinate: str | None = None
    member: str | None = None
    coordinates: list[str] = field(default_factory=list)
    factor: float | None = None
    equivalents: list[Candidate] = field(default_factory=list)

    def alike(self) -> list[Candidate]:
        """This candidate and its equivalents."""
        return [self, *self.equivalents]

    def to_dict(self) -> dict:
        out = {"term": self.term, "kind": self.kind, "score": self.score, "parts": dict(self.parts)}
        for key in ("row", "coordinate", "member", "factor"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.coordinates:
            out["coordinates"] = list(self.coordinates)
        if self.equivalents:
            out["equivalents"] = [e.to_dict() for e in self.equivalents]
        return out


@dataclass
class Diagnosis:
    """The best one-term explanations of the evidence, best first (one per class of look-alikes)."""

    train: str
    candidates: list[Candidate]
    reference_score: float | None  # the unchanged reference's score; None when the evidence lacks coordinates
    held: list[str]  # the reference's coordinates the evidence lacks
    evidence: dict[str, int]  # how much evidence: frequencies at rest, shapes, frequencies at speed
    tried: int  # one-term changes scored
    reduced_to: int | None = None  # coordinates of the reduced reference it was compared with, if reduced

    @property
    def best(self) -> Candidate:
        return self.candidates[0]

    @property
    def agrees(self) -> bool:
        """The reference itself explains the evidence (to round-off)."""
        return self.reference_score is not None and self.reference_score <= AGREEMENT

    def lines(self) -> list[str]:
        """A few plain sentences."""
        best, out = self.best, []
        if self.agrees and self.reduced_to:
            out.append(f"No single-term mistake: agrees with the reference reduced to its {self.reduced_to} "
                       f"coordinates (score {self.reference_score:.2g}); what differs from the full reference is "
                       "the reduction itself (the coordinates it holds or ties), not a wrong term.")
        elif self.agrees:
            out.append(f"No single-term mistake: agrees with the reference (score {self.reference_score:.2g}).")
        else:
            against = (f"the reference scores {self.reference_score:.3g}" if self.reference_score is not None
                       else f"the evidence lacks {len(self.held)} of the reference's coordinates")
            out.append(f"Most likely: {best.term} (score {best.score:.3g}; {against}).")
            if best.score > AGREEMENT:
                out.append("No one-term change explains the evidence to round-off: the mistake may be in more "
                           "than one term, or in one this diagnosis does not try.")
        if best.equivalents:
            out.append(f"This evidence cannot tell it from: {'; '.join(e.term for e in best.equivalents)}.")
        out += [f"Next: {c.term} (score {c.score:.3g})." for c in self.candidates[1:]]
        seen = [f"{self.evidence['rest']} frequencies at rest"]
        if self.evidence["shapes"]:
            seen.append(f"{self.evidence['shapes']} mode shapes")
        if self.evidence["speed"]:
            seen.append(f"{self.evidence['speed']} frequencies at speed")
        out.append(f"Evidence: {', '.join(seen)}; {self.tried} one-term changes tried.")
        if not self.evidence["speed"]:
            out.append("Gyroscopic and centripetal terms are not checked: they need frequencies at speed.")
        return out

    def summary(self) -> str:
        return "\n".join(self.lines())

    def to_dict(self) -> dict:
        return {"train": self.train, "agrees": self.agrees, "reduced_to": self.reduced_to,
                "reference_score": self.reference_score,
                "held": list(self.held), "evidence": dict(self.evidence), "tried": self.tried,
                "candidates": [c.to_dict() for c in self.candidates]}


@dataclass
class _Trial:
    """A candidate and its change: K += sum c v v^T, M -> S M S (S = diag(scale)), G or K_centripetal dropped."""

    candidate: Candidate
    outer: tuple[tuple[float, np.ndarray], ...] = ()
    scale: np.ndarray | None = None
    gyroscopic: bool = True
    centripetal: bool = True
    rest: np.ndarray | None = None  # frequencies at rest compared
    speed: np.ndarray | None = None  # frequencies at speed compared


class _Base:
    """The reference over the evidence's coordinates (held where the evidence lacks some), whitened."""

    def __init__(self, model: LumpedModel, labels: list[str]):
        every = model.dofs.labels()
        index = {label: i for i, label in enumerate(every)}
        unknown = [label for label in labels if label not in index]
        if unknown or len(set(labels)) != len(labels):
            raise GearcheckError(f"{model.spec.name}: evidence coordinates must be distinct reference coordinates "
                                 f"({', '.join(unknown) or 'repeated'})")
        self.keep = np.array(sorted(index[label] for label in labels))
        self.order = np.argsort([index[label] for label in labels])  # evidence rows in the reference's order
        self.labels = [every[i] for i in self.keep]
        self.held = [label for label in every if label not in set(labels)]
        sub = np.ix_(self.keep, self.keep)
        self.M, self.K = model.M[sub], model.K_mean[sub]
        self.G, self.Kc = model.G[sub], model.K_centripetal[sub]
        self.Linv = sla.solve_triangular(np.linalg.cholesky(self.M), np.eye(len(self.keep)), lower=True)
        self.Kt = self.whiten(self.K)
        self.rows = [(f"row {r.name}", r.name, r.stiffness, r.a[self.keep]) for r in model.rows if r.stiffness]
        self.rows += [(f"mesh {mesh.id}", mesh.id, k, a[self.keep])
                      for mesh, a, k in zip(model.spec.meshes, model.mesh_rows, model.excitation.mean_stiffness)]
        self.rows = [row for row in self.rows if np.any(row[3])]
        self.inertias = []  # (term, member, coordinates, mask)
        position = {label: i for i, label in enumerate(self.labels)}
        for member in model.spec.members:
            dofs = [d for m, d in model.dofs.names if m == member]
            for term, group in ((f"{member} mass", dofs[:2]), (f"{member}.theta inertia", ["theta"]),
                                (f"{member}.{AXIAL} mass", [d for d in dofs if d == AXIAL])):
                coordinates = [f"{member}.{d}" for d in group if f"{member}.{d}" in position]
                if coordinates:
                    mask = np.zeros(len(self.labels), bool)
                    mask[[position[c] for c in coordinates]] = True
                    self.inertias.append((term, member, coordinates, mask))

    @property
    def n(self) -> int:
        return len(self.labels)

    def whiten(self, K: np.ndarray) -> np.ndarray:
        """L^-1 K L^-T (stacks allowed): K x = w^2 M x becomes a symmetric eigenproblem."""
        return self.Linv @ K @ self.Linv.T

    def changed(self, trial: _Trial) -> tuple[np.ndarray, np.ndarray]:
        """Whitened stiffness of a trial and its mass scale (ones when M is unchanged)."""
        if trial.scale is None:
            Kt = self.Kt.copy()
            for c, v in trial.outer:
                b = self.Linv @ v
                Kt += c * np.outer(b, b)
            return Kt, np.ones(self.n)
        return self.whiten(self.K / np.outer(trial.scale, trial.scale)), trial.scale

    def speed_frequencies(self, trial: _Trial) -> np.ndarray:
        """The trial's gyroscopic frequencies (Hz) at the operating speed, counted as
        :func:`gearcheck.shared.modal.speed_modal_result` counts them.  With K positive definite every root is
        +/- i omega and omega^2 are the eigenvalues, each twice, of S^T S, S = A^-1/2 B A^-T/2 the skew-symmetric
        form of A y' = B y, A = diag(K, M), B = [[0, K], [-K, -G]] (Meirovitch 1974); otherwise the roots of
        the first-order form: one per conjugate pair, a divergence once, rigid roots as half as many zeros."""
        K = self.K + sum((c * np.outer(v, v) for c, v in trial.outer), np.zeros_like(self.K))
        M = self.M if trial.scale is None else self.M * np.outer(trial.scale, trial.scale)
        G = self.G if trial.gyroscopic else np.zeros_like(self.G)
        if trial.centripetal:
            K = K + self.Kc
        n = self.n
        try:
            Lk = np.linalg.cholesky(K)
        except np.linalg.LinAlgError:
            first_order = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, G)]])
            s = np.linalg.eigvals(first_order)
            largest = np.max(np.abs(s))
            rigid = np.abs(s) ** 2 <= RIGID_TOLERANCE * largest**2
            real = np.abs(s.imag) <= STABILITY_TOLERANCE * largest
            kept = s[~rigid & ((s.imag > STABILITY_TOLERANCE * largest) | (real & (s.real > 0)))]
            omega = np.concatenate([np.zeros((int(np.sum(rigid)) + 1) // 2), np.abs(kept.imag)])
            return np.sort(omega) / (2.0 * np.pi)
        Lm_inv = self.Linv if trial.scale is None else self.Linv / trial.scale  # S M S = (S L)(S L)^T
        S = np.zeros((2 * n, 2 * n))
        S[:n, n:] = Lk.T @ Lm_inv.T
        S[n:, :n] = -S[:n, n:].T
        S[n:, n:] = -Lm_inv @ G @ Lm_inv.T
        w2 = np.linalg.eigvalsh(S.T @ S)[::2]
        w2[w2 <= RIGID_TOLERANCE * w2[-1]] = 0.0
        return np.sqrt(w2) / (2.0 * np.pi)


def _eigh(stack: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and vectors of a stack of symmetric matrices, one LAPACK call each (steadier than numpy's
    batched call where BLAS threads contend for the cores)."""
    pairs = [sla.eigh(A, check_finite=False) for A in stack]
    return np.array([w for w, _ in pairs]).reshape(len(stack), -1), np.array([v for _, v in pairs])


def _errors(f: np.ndarray, target: np.ndarray) -> np.ndarray:
    """rms over the modes of |f - f_e| / max(f, f_e) (stacks of f along axis 0 allowed; 0 where both are 0)."""
    f = f[..., :len(target)]
    top = np.maximum(f, target)
    counted = top > 0
    err = np.where(counted, np.abs(f - target) / np.where(counted, top, 1.0), 0.0)
    return np.sqrt(np.sum(err**2, axis=-1) / np.maximum(np.sum(counted, axis=-1), 1))


def _frequencies(f, n: int, where: str) -> np.ndarray:
    """Evidence frequencies checked: between 1 and n of them, ascending."""
    f = np.asarray(f, dtype=float)
    if f.ndim != 1 or not 0 < len(f) <= n or np.any(np.diff(f) < 0) or np.any(f < 0):
        raise GearcheckError(f"evidence frequencies {where} must be 1 to {n} ascending values in Hz, "
                             f"got {np.array2string(f, threshold=8)}")
    return f


def _cuts(f: np.ndarray) -> np.ndarray:
    """True between consecutive modes of different frequency (stacks along axis 0 allowed)."""
    a, b = f[..., :-1], f[..., 1:]
    same = (np.abs(a - b) <= DEGENERACY_TOLERANCE * np.maximum(np.abs(a), np.abs(b))) | ((a == 0) & (b == 0))
    return ~same


class _Scorer:
    """The at-rest part of the score of stacks of whitened stiffness matrices."""

    def __init__(self, base: _Base, evidence: Evidence):
        self.base = base
        self.f = _frequencies(evidence.frequencies, base.n, "at rest")
        self.m = len(self.f)
        self.E = self.W = None
        if evidence.shapes is not None:
            E = np.asarray(evidence.shapes, dtype=float)
            if E.shape != (base.n, self.m):
                raise GearcheckError(f"evidence shapes are {E.shape}, expected ({base.n}, {self.m})")
            self.E = E[base.order]
            if evidence.mass is not None:
                self.W = np.asarray(evidence.mass, dtype=float)[np.ix_(base.order, base.order)]
                self.E_norm = np.einsum("ia,ij,ja->a", self.E, self.W, self.E)
        self.cut = _cuts(self.f)

    def frequencies(self, lam: np.ndarray) -> np.ndarray:
        """Frequencies (Hz) of eigenvalue stacks, rigid ones zeroed as :func:`generalized_modes` does."""
        lam = np.where(np.abs(lam) < RIGID_TOLERANCE * np.max(np.abs(lam), axis=-1, keepdims=True), 0.0, lam)
        return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi)

    def score(self, Kt: np.ndarray, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(frequency part, shape part, compared frequencies) of whitened stiffness stacks Kt (N, n, n) with
        mass scales (N, n)."""
        parts = [self._score(Kt[i:i + BATCH], scale[i:i + BATCH]) for i in range(0, len(Kt), BATCH)]
        return tuple(np.concatenate(p) for p in zip(*parts))

    def _score(self, Kt, scale):
        if self.E is None:
            f = self.frequencies(np.linalg.eigvalsh(Kt))[:, :self.m]
            return _errors(f, self.f), np.zeros(len(Kt)), f
        lam, Z = _eigh(Kt)
        f = self.frequencies(lam)[:, :self.m]
        Y = self.base.Linv.T @ Z[:, :, :self.m]  # M-orthonormal; the shapes are Y / scale
        if self.W is not None:  # the candidate's modes in the span of the evidence's (W-orthogonal) ones
            X = Y / scale[:, :, None]
            X_W = np.swapaxes(X, 1, 2) @ self.W
            mac = (X_W @ self.E) ** 2 / (np.einsum("nai,nia->na", X_W, X)[:, :, None] * self.E_norm)
        else:  # the evidence's modes in the span of the candidate's (M'-orthonormal, M' = S M S) ones
            SE = scale[:, :, None] * self.E
            SE_M = np.swapaxes(SE, 1, 2) @ self.base.M
            mac = (SE_M @ Y) ** 2 / np.einsum("nai,nia->na", SE_M, SE)[:, :, None]
        group = np.concatenate([np.zeros((len(Kt), 1), int), np.cumsum(_cuts(f) & self.cut, axis=1)], axis=1)
        share = np.sum(np.where(group[:, :, None] == group[:, None, :], mac, 0.0), axis=2)
        return _errors(f, self.f), np.mean(1.0 - np.clip(share, 0.0, 1.0), axis=1), f


def _exact_trials(base: _Base, speed: bool) -> list[_Trial]:
    """The reference (or its held version), every row coefficient dropped or flipped, and the frame terms."""
    if base.held:
        reference = Candidate(f"coordinates held: {', '.join(base.held)}", "held coordinates",
                              coordinates=list(base.held))
    else:
        reference = Candidate("no change: the reference itself", "no mistake")
    trials = [_Trial(reference)]
    for prefix, name, k, a in base.rows:
        nonzero = np.where(np.abs(a) > COEFFICIENT_FLOOR * np.max(np.abs(a)))[0]
        for j in nonzero:
            coordinate = base.labels[j]
            dropped = a.copy()
            dropped[j] = 0.0
            trials.append(_Trial(Candidate(f"{prefix}: coefficient of {coordinate} dropped", "dropped coupling",
                                           row=name, coordinate=coordinate), ((k, dropped), (-k, a))))
            if len(nonzero) > 1:  # flipping a row's only coefficient leaves a a^T as it is
                flipped = a.copy()
                flipped[j] = -a[j]
                trials.append(_Trial(Candidate(f"{prefix}: sign of the {coordinate} coefficient flipped",
                                               "sign error", row=name, coordinate=coordinate),
                                     ((k, flipped), (-k, a))))
    if speed:
        trials.append(_Trial(Candidate("gyroscopic terms missing", "gyroscopic"), gyroscopic=False))
        trials.append(_Trial(Candidate("centripetal terms missing", "centripetal"), centripetal=False))
    return trials


def _fitted_trials(base: _Base, scorer: _Scorer) -> list[_Trial]:
    """Every row's stiffness and every member inertia times a factor fitted to the at-rest frequencies: the best
    of a grid, then Gauss-Newton steps in log factor while they move."""
    B = np.array([base.Linv @ a for *_, a in base.rows]).reshape(-1, base.n)  # whitened rows
    k = np.array([row[2] for row in base.rows])
    masks = np.array([mask for *_, mask in base.inertias]).reshape(-1, base.n)
    n_rows, n = len(B), len(B) + len(masks)

    def solve(p, idx, vectors):  # the families idx (rows first, then inertias) at log factors p
        row, inertia = idx < n_rows, idx >= n_rows
        r, i = idx[row], idx[inertia] - n_rows
        Kt = np.empty((len(idx), base.n, base.n))
        Kt[row] = base.Kt + ((np.exp(p[row]) - 1.0) * k[r])[:, None, None] * B[r, :, None] * B[r, None, :]
        scale = np.where(masks[i], np.exp(0.5 * p[inertia])[:, None], 1.0)
        Kt[inertia] = base.whiten(base.K / (scale[:, :, None] * scale[:, None, :]))
        if not vectors:
            return scorer.frequencies(np.linalg.eigvalsh(Kt))[:, :scorer.m]
        lam, Z = _eigh(Kt)
        f = scorer.frequencies(lam)[:, :scorer.m]
        lam, Z = lam[:, :scorer.m], Z[:, :, :scorer.m]
        dlam = np.empty(lam.shape)  # eigenvalue derivatives in log factor (Fox & Kapoor 1968)
        dlam[row] = (np.exp(p[row]) * k[r])[:, None] * np.einsum("ri,ria->ra", B[r], Z[row]) ** 2
        Y = base.Linv.T @ Z[inertia]  # M-orthonormal shapes times the mass scale
        dlam[inertia] = -lam[inertia] * np.einsum("ria,ria->ra", masks[i][:, :, None] * Y, base.M @ Y)
        return f, np.where(lam > 0, f * dlam / (2.0 * np.where(lam > 0, lam, 1.0)), 0.0)

    elastic = scorer.f > 0
    target = scorer.f[elastic]
    every = np.arange(n)
    grid = np.array([np.sum((solve(np.full(n, g), every, False)[:, elastic] / target - 1.0) ** 2, axis=1)
                     for g in GRID])
    p = GRID[np.argmin(grid, axis=0)]
    best_p, best = p.copy(), grid.min(axis=0)
    low, high = np.log(FACTOR_BOUNDS)
    active = every
    for _ in range(NEWTON_STEPS):
        q = p[active]
        f, df = solve(q, active, True)
        r, J = f[:, elastic] / target - 1.0, df[:, elastic] / target
        value = np.sum(r**2, axis=1)
        better = value < best[active]
        best_p[active[better]], best[active[better]] = q[better], value[better]
        step = -np.sum(r * J, axis=1) / (np.sum(J * J, axis=1) + 1e-16)  # damped: a row no mode feels stays put
        p[active] = np.clip(q + np.clip(step, -MAX_STEP, MAX_STEP), low, high)
        active = active[np.abs(p[active] - q) > 1e-12]
        if not active.size:
            break
    trials = []
    changes = np.abs(best_p) > FACTOR_RESOLUTION
    for (prefix, name, k_row, a), q in zip(base.rows, best_p[:n_rows]):
        factor = float(np.exp(q))
        trials.append(_Trial(Candidate(f"{prefix} stiffness x {factor:.4g}", "stiffness", row=name, factor=factor),
                             (((factor - 1.0) * k_row, a),)))
    for (term, member, coordinates, mask), q in zip(base.inertias, best_p[n_rows:]):
        factor = float(np.exp(q))
        trials.append(_Trial(Candidate(f"{term} x {factor:.4g}", "inertia", member=member,
                                       coordinates=list(coordinates), factor=factor),
                             scale=np.where(mask, math.sqrt(factor), 1.0)))
    return [t for t, change in zip(trials, changes) if change]


def _classes(trials: list[_Trial], reference: _Trial) -> list[list[_Trial]]:
    """The trials in classes this evidence cannot tell apart (scores and every compared frequency the same to
    EQUIVALENCE), best first; the reference heads its own class, whatever looks like it joins it."""
    trials = [reference] + sorted((t for t in trials if t is not reference), key=lambda t: t.candidate.score)
    signature = np.array([t.rest if t.speed is None else np.concatenate([t.rest, t.speed]) for t in trials])
    score = np.array([t.candidate.score for t in trials])
    heads, classes = np.zeros(len(trials), int), []
    for i, t in enumerate(trials):
        h = heads[:len(classes)]
        x, y = signature[h], signature[i]
        alike = ((np.abs(score[h] - score[i]) <= AGREEMENT + EQUIVALENCE * score[h])
                 & np.all(np.abs(x - y) <= EQUIVALENCE * np.maximum(x, y), axis=1))
        if np.any(alike):
            classes[int(np.argmax(alike))].append(t)
        else:
            heads[len(classes)] = i
            classes.append([t])
    return sorted(classes, key=lambda c: c[0].candidate.score)


def diagnose(model: LumpedModel, evidence: Evidence, top: int = 3) -> Diagnosis:
    """Rank one-term changes of the reference ``model`` by how well they explain ``evidence``: the ``top``
    classes of look-alike candidates, best first (the reference first when it agrees)."""
    base = _Base(model, list(evidence.labels))
    scorer = _Scorer(base, evidence)
    speed_evidence = evidence.frequencies_at_speed
    if speed_evidence is not None:
        speed_evidence = _frequencies(speed_evidence, base.n, "at speed")
    trials = _exact_trials(base, speed_evidence is not None) + _fitted_trials(base, scorer)
    changed = [base.changed(t) for t in trials]
    rest, shapes, f = scorer.score(np.array([c[0] for c in changed]), np.array([c[1] for c in changed]))
    partial = rest + shapes
    for t, r, s, fi in zip(trials, rest, shapes, f):
        t.rest = fi
        t.candidate.parts = {"rest": float(r)} | ({"shapes": float(s)} if scorer.E is not None else {})
        t.candidate.score = float(r + s)
    reference = trials[0]
    if speed_evidence is None:
        ranked = _classes(trials, reference)
    else:
        def at_speed(t):
            t.speed = base.speed_frequencies(t)[:len(speed_evidence)]
            t.candidate.parts["speed"] = float(_errors(t.speed, speed_evidence))
            t.candidate.score += t.candidate.parts["speed"]

        at_speed(reference)
        evaluated = [reference]
        for i in np.argsort(partial, kind="stable"):
            if trials[i] is reference:
                continue
            certain = [t for t in evaluated if t.candidate.score <= partial[i]]  # no trial left scores less
            if len(certain) >= top and sum(c[0].candidate.score <= partial[i]
                                           for c in _classes(certain, reference)) >= top:
                break
            at_speed(trials[i])
            evaluated.append(trials[i])
        ranked = _classes(evaluated, reference)
    if not base.held and reference.candidate.score <= AGREEMENT:  # the reference first when it agrees
        ranked.sort(key=lambda c: c[0] is not reference)
    candidates = [replace(c[0].candidate, equivalents=[] if c[0] is reference else [t.candidate for t in c[1:]])
                  for c in ranked[:top]]  # what looks like the reference is a change this evidence cannot see
    counts = {"rest": scorer.m, "shapes": 0 if scorer.E is None else scorer.m,
              "speed": 0 if speed_evidence is None else len(speed_evidence)}
    return Diagnosis(model.spec.name, candidates, None if base.held else reference.candidate.score, base.held,
                     counts, len(trials))


def diagnose_side(model: LumpedModel, side, modal=None, top: int = 3) -> Diagnosis:
    """The diagnosis of a user's model as the cross-check holds it (a :class:`~gearcheck.shared.side.Side`)
    against the reference ``model``: its frequencies, its shapes and its frequencies at the operating speed where
    it has them.  A model given as
    matrices over the train's members is compared with the reference reduced to its coordinates
    (:func:`constrained`), so a torsional model is held to the reference with its translations tied as its
    map ties them.  ``modal``: the side's modes when already computed."""
    modal = side.modes() if modal is None else modal
    try:
        at_speed = side.modes_at_speed(model.spec.operating.input_speed).frequencies
    except UnsupportedError:
        at_speed = None
    linear = side.linear
    if linear is not None and all("." in c and c.rsplit(".", 1)[0] in model.spec.members for c in linear.coordinates):
        T, _ = linear.to_physical(model.dofs.labels())
        reduced = constrained(model, linear.coordinates, T)
        diagnosis = diagnose(reduced, Evidence(linear.coordinates, modal.frequencies, modal.shapes, linear.M,
                                               at_speed), top)
        if len(linear.coordinates) < model.n:
            diagnosis.reduced_to = len(linear.coordinates)
        return diagnosis
    try:
        labels, mass, shapes = side.physical_modes(modal)
    except UnsupportedError:  # a recording without mode shapes
        labels, mass, shapes = model.dofs.labels(), None, None
    return diagnose(model, Evidence(labels, modal.frequencies, shapes, mass, at_speed), top)
