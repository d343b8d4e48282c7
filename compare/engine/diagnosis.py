"""Which term of a user's lumped model is wrong: a diagnosis by one-term changes of the reference.

A user's lumped gear-train model that disagrees with the reference (Lin & Parker 1999; Kiracofe & Parker
2007 for several stages) usually differs in one term.  Every candidate here is the reference changed in
one term, its modes computed exactly (an eigenproblem per candidate, not first-order sensitivities) and
scored against what is known of the suspect model (:class:`Evidence`):

* a deflection row (a bearing, support, coupling or shaft row; a mesh's line-of-action row, named by its
  mesh id) with one coefficient dropped ("dropped coupling") or its sign flipped ("sign error");
* a row's stiffness times a fitted factor ("stiffness");
* a spring the train lacks, fitted: from a coordinate to ground, or between two members' coordinates of the same
  kind (x and x, theta and theta, radial and radial: n(n-1)/2 pairs at most, fewer where the kinds differ), not
  where a row already is that spring ("extra spring"; a spring to ground removes a rigid-body mode);
* a row's rotation coefficient, or a stiffness entry with a rotation coordinate, times r^p (p = +-1, +-2, r the
  member's radius as its rows give it: a gear's base radius, the carrier's pin circle): u = r theta turns
  K_theta = D K_u D, D = diag(r) on the rotations, so a slip of convention scales exactly those entries, e.g.
  N r_c k written where N r_c^2 k belongs ("radius power");
* a stage's central stiffness entry with the planets' share (Lin & Parker 1999's sums over the planets) written
  for n' = 1, ..., N + 1 planets, n' != N ("planet count", e.g. K_cc = 3 k_p for N = 4);
* a member's mass on its two transverse translations, its rotational inertia or its axial mass times a
  fitted factor ("inertia": the member's entries of M), named as a convention when the factor is one: cos^2
  alpha or its inverse (I = m r^2 with the pitch radius for the base radius), r^+-2 (u = r theta);
* the Coriolis matrix dropped ("gyroscopic"), the centripetal stiffness dropped ("centripetal") or written as
  Lin & Parker's (1999) softening -m Omega^2 alone, without the rigid-turn correction of
  :mod:`gearcheck.lumped.assembly` ("rigid-turn correction"), seen only in the frequencies at speed, where the
  degenerate pairs split (Cooley & Parker 2012);
* when the evidence lacks coordinates: the reference with them held ("held coordinates"); then every other
  candidate is a one-term change of that held reference;
* when no single change explains the evidence: pairs of exact changes ("pair"), each of the few best singles with
  every other exact change, reported first only when a pair scores below :data:`PAIR_MARGIN` times the best
  single.

The evidence's zero-frequency modes are counted against the reference's: rigid-body modes lost or gained are
said first.

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
them among the best (branch and bound: the at-speed part of a score is never negative).  An exact change heads
a class of look-alikes before a fitted one (a fitted spring to ground matches an entry's exact change).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.linalg as sla

from gearcheck.compare.engine.reduction import reduction_basis
from gearcheck.lumped.assembly import LumpedModel
from gearcheck.lumped.constraints import constrained
from gearcheck.train.spec import AXIAL, ROTATION
from gearcheck.lumped.modal import modes, modes_at_speed
from gearcheck.shared.errors import GearcheckError, UnsupportedError
from gearcheck.shared.modal import DEGENERACY_TOLERANCE, RIGID_TOLERANCE, STABILITY_TOLERANCE

KINDS = ("no mistake", "held coordinates", "dropped coupling", "sign error", "stiffness", "inertia", "gyroscopic",
         "centripetal", "rigid-turn correction", "extra spring", "radius power", "planet count", "pair")
AGREEMENT = 1e-9  # a score below it is round-off: the candidate explains the evidence
FACTOR_BOUNDS = (1e-3, 1e3)  # fitted factors: wide enough for a unit slip (mm for m, g for kg)
COEFFICIENT_FLOOR = 1e-12  # a row coefficient below this times the row's largest is a zero (cos(pi/2))
FACTOR_RESOLUTION = 1e-6  # a fitted factor closer to 1 is no change (the reference itself)
EQUIVALENCE = 1e-7  # candidates whose frequencies agree to this (relative) and whose scores agree look alike
GRID = np.log(np.geomspace(*FACTOR_BOUNDS, 7))  # start of the fits: factors 1e-3, 1e-2, ..., 1e3
NEWTON_STEPS = 30
MAX_STEP = 2.0  # largest Gauss-Newton step in log factor
BATCH = 256  # candidates scored together (memory)
POWERS = (-2, -1, 1, 2)  # a coefficient or stiffness entry times r^p: u = r theta converted too often or not at all
CONVENTION = 1e-4  # a fitted inertia factor this close (relative) to a convention's factor is named as that one
PAIR_POOL = 6  # pairs start from this many best exact single changes (a row on each of 6 planets)
PAIR_MARGIN = 1e-2  # a pair is reported when it scores below this times the best single change


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
    (or the coordinates held, or those an extra spring joins); ``factor``: the fitted or applied factor;
    ``stiffness``: an extra spring's fitted stiffness; ``parts``: the score's terms (rest, shapes, speed);
    ``equivalents``: the other candidates this evidence cannot tell from this one; ``pair``: a pair's two changes."""

    term: str
    kind: str
    score: float = math.nan
    parts: dict[str, float] = field(default_factory=dict)
    row: str | None = None
    coordinate: str | None = None
    member: str | None = None
    coordinates: list[str] = field(default_factory=list)
    factor: float | None = None
    stiffness: float | None = None
    equivalents: list[Candidate] = field(default_factory=list)
    pair: list[Candidate] = field(default_factory=list)

    def alike(self) -> list[Candidate]:
        """This candidate and its equivalents."""
        return [self, *self.equivalents]

    def to_dict(self) -> dict:
        out = {"term": self.term, "kind": self.kind, "score": self.score, "parts": dict(self.parts)}
        for key in ("row", "coordinate", "member", "factor", "stiffness"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        if self.coordinates:
            out["coordinates"] = list(self.coordinates)
        for key in ("equivalents", "pair"):
            if getattr(self, key):
                out[key] = [e.to_dict() for e in getattr(self, key)]
        return out


@dataclass
class Diagnosis:
    """The best one-term explanations of the evidence, best first (one per class of look-alikes); a pair of
    changes first when it explains the evidence clearly better than any one."""

    train: str
    candidates: list[Candidate]
    reference_score: float | None  # the unchanged reference's score; None when the evidence lacks coordinates
    held: list[str]  # the reference's coordinates the evidence lacks
    evidence: dict[str, int]  # how much evidence: frequencies at rest, shapes, frequencies at speed
    tried: int  # one-term changes scored
    reduced_to: int | None = None  # coordinates of the reduced reference it was compared with, if reduced
    reduction: str | None = None  # what that reference did with the others: "held" or "condensed"
    rigid_modes: dict[str, int] = field(default_factory=dict)  # zero frequencies: evidence's and reference's
    pairs: int = 0  # pairs of changes scored (when no one-term change explains the evidence)

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
            others = {"held": "the others held", "condensed": "the others condensed out (Guyan 1965)"}
            out.append(f"No single-term mistake: agrees with the reference reduced to its {self.reduced_to} "
                       f"coordinates, {others.get(self.reduction, 'the others held')} (score "
                       f"{self.reference_score:.2g}); what differs from the full reference is the reduction itself "
                       "(the coordinates it holds or ties), not a wrong term.")
        elif self.agrees:
            out.append(f"No single-term mistake: agrees with the reference (score {self.reference_score:.2g}).")
        else:
            against = (f"the reference scores {self.reference_score:.3g}" if self.reference_score is not None
                       else f"the evidence lacks {len(self.held)} of the reference's coordinates")
            margin = (f"; the next scores {self.candidates[1].score:.3g}" if len(self.candidates) > 1 else "")
            out.append(f"Most likely: {best.term} (score {best.score:.3g}; {against}{margin}).")
            if best.score > AGREEMENT:
                out.append("No one-term change explains the evidence to round-off: the mistake may be in more "
                           "than one term, or in one this diagnosis does not try.")
        rigid = self.rigid_modes
        lost = rigid.get("reference", 0) - rigid.get("evidence", 0)
        counts = f"the evidence has {rigid.get('evidence')}, the reference {rigid.get('reference')}"
        if lost > 0:
            out.insert(0, f"Rigid-body modes lost: {lost} ({counts}): something holds what nothing in the train "
                          "holds, a spring to ground or a stiffness entry that a rigid turn strains.")
        elif lost < 0:
            out.insert(0, f"Rigid-body modes gained: {-lost} ({counts}): a support, shaft or coupling is missing, "
                          "or a stiffness entry no longer holds what it should.")
        if best.equivalents:
            out.append(f"This evidence cannot tell it from: {'; '.join(e.term for e in best.equivalents)}.")
        out += [f"Next: {c.term} (score {c.score:.3g})." for c in self.candidates[1:]]
        seen = [f"{self.evidence['rest']} frequencies at rest"]
        if self.evidence["shapes"]:
            seen.append(f"{self.evidence['shapes']} mode shapes")
        if self.evidence["speed"]:
            seen.append(f"{self.evidence['speed']} frequencies at speed")
        pairs = f" and {self.pairs} pairs" if self.pairs else ""
        out.append(f"Evidence: {', '.join(seen)}; {self.tried} one-term changes{pairs} tried.")
        if not self.evidence["speed"]:
            out.append("Gyroscopic and centripetal terms are not checked: they need frequencies at speed.")
        return out

    def summary(self) -> str:
        return "\n".join(self.lines())

    def to_dict(self) -> dict:
        return {"train": self.train, "agrees": self.agrees, "reduced_to": self.reduced_to, "reduction": self.reduction,
                "reference_score": self.reference_score,
                "held": list(self.held), "evidence": dict(self.evidence), "tried": self.tried,
                "rigid_modes": dict(self.rigid_modes), "pairs": self.pairs,
                "candidates": [c.to_dict() for c in self.candidates]}


@dataclass
class _Trial:
    """A candidate and its change: K += sum c v v^T, M -> S M S (S = diag(scale)), G dropped, K_centripetal
    replaced by ``frame``; ``fitted``: its factor fitted (an exact change heads a class of look-alikes)."""

    candidate: Candidate
    outer: tuple[tuple[float, np.ndarray], ...] = ()
    scale: np.ndarray | None = None
    gyroscopic: bool = True
    frame: np.ndarray | None = None
    fitted: bool = False
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
        members = model.spec.members
        self.member = [members[label.rsplit(".", 1)[0]] for label in self.labels]
        self.rotation = np.array([label.endswith(f".{ROTATION}") for label in self.labels])
        self.radii = self._radii(model, index)
        self.conventions = {}  # member -> {factor: what a fitted inertia factor equal to it means}
        for j in np.where(self.rotation)[0]:
            m = self.member[j]
            named = {r**p: f"= r^{p:+d}, r = {r:.6g} m: u = r theta converted once too often or not at all"
                     for r in self.radii.get(j, []) for p in (-2, 2)}
            gear = next(iter(m.gears.values()), None)
            if gear is not None and m.reference_radius > gear.base_radius:
                c2 = (gear.base_radius / m.reference_radius) ** 2
                named |= {c2: "= cos^2 alpha: m r^2 with the base radius for the pitch radius",
                          1.0 / c2: "= 1/cos^2 alpha: m r^2 with the pitch radius for the base radius"}
            self.conventions[m.id] = named
        self.planet_sums = self._planet_sums(model, index)
        translation = ~self.rotation & np.array([not label.endswith(f".{AXIAL}") for label in self.labels])
        self.Kc_textbook = np.diag(np.where(translation, np.diag(self.Kc), 0.0))  # the softening -m Omega^2 only
        self.springs = self._springs()
        lam = np.linalg.eigvalsh(self.Kt)
        self.rigid = int(np.sum(lam <= RIGID_TOLERANCE * np.max(np.abs(lam))))

    def _radii(self, model: LumpedModel, index: dict[str, int]) -> dict[int, list[float]]:
        """The radii r of u = r theta per rotation coordinate: its coefficients' sizes (other than 1) in the rows
        that join it to other coordinates, held ones included (a gear's base radius in its meshes, the carrier's
        pin circle in the planet bearings)."""
        radii: dict[int, list[float]] = {}
        for a in [r.a for r in model.rows if r.stiffness] + list(model.mesh_rows):
            nonzero = np.abs(a) > COEFFICIENT_FLOOR * np.max(np.abs(a))
            if np.sum(nonzero) < 2:
                continue
            for j, label in enumerate(self.labels):
                if not (self.rotation[j] and nonzero[index[label]]):
                    continue
                r = abs(float(a[index[label]]))
                known = radii.setdefault(j, [])
                if not math.isclose(r, 1.0, rel_tol=1e-9) and not any(math.isclose(r, x, rel_tol=1e-9)
                                                                     for x in known):
                    known.append(r)
        return radii

    def _planet_sums(self, model: LumpedModel, index: dict[str, int]) -> list[tuple[int, np.ndarray, list[int]]]:
        """Per stage with planets: their number N, the planets' rows' share of K over the evidence's coordinates
        (a sum over the planets, Lin & Parker 1999) and the stage's central coordinates it reaches."""
        out, every = [], model.dofs.labels()
        full = [(r.stiffness, r.a) for r in model.rows if r.stiffness]
        full += list(zip(model.excitation.mean_stiffness, model.mesh_rows))
        for stage in dict.fromkeys(m.stage for m in model.spec.members.values()):
            planets = {m.id for m in model.spec.members.values() if m.stage == stage and m.is_planet}
            if len(planets) < 2:
                continue
            columns = [index[label] for label in every if label.rsplit(".", 1)[0] in planets]
            P = sum((k * np.outer(a, a) for k, a in full if np.any(a[columns])), np.zeros((len(every),) * 2))
            central = [i for i, m in enumerate(self.member) if m.stage == stage and m.id not in planets]
            out.append((len(planets), P[np.ix_(self.keep, self.keep)], central))
        return out

    def _springs(self) -> list[tuple[str, list[str], np.ndarray, float]]:
        """Springs the reference lacks (term, coordinates, deflection row, stiffness scale): one from each
        coordinate to ground, and one between each two members' coordinates of the same kind (x and x, theta and
        theta, ...), scaled by their diagonal stiffness; not where a row is already that spring (then it is that
        row's stiffness candidate)."""
        out, d = [], np.diag(self.K)
        rows = [a / np.linalg.norm(a) for *_, a in self.rows]

        def new(v):
            return not any(abs(abs(a @ v) / np.linalg.norm(v) - 1.0) <= 1e-12 for a in rows)

        dof = [label.rsplit(".", 1)[1] for label in self.labels]
        for i, label in enumerate(self.labels):
            if d[i] > 0 and new(np.eye(self.n)[i]):
                out.append((f"extra spring from {label} to ground", [label], np.eye(self.n)[i], d[i]))
        for i in range(self.n):
            for j in range(i + 1, self.n):
                v = np.eye(self.n)[i] - np.eye(self.n)[j]
                if dof[i] == dof[j] and self.member[i] is not self.member[j] and d[i] > 0 and d[j] > 0 and new(v):
                    out.append((f"extra spring between {self.labels[i]} and {self.labels[j]}",
                                [self.labels[i], self.labels[j]], v, math.sqrt(d[i] * d[j])))
        return out

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
        K = K + (self.Kc if trial.frame is None else trial.frame)
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


def _entry(base: _Base, i: int, j: int, d: float) -> tuple[tuple[float, np.ndarray], ...]:
    """K_ij and K_ji changed by d, as outer products."""
    e = np.eye(base.n)
    if i == j:
        return ((d, e[i]),)
    return ((0.5 * d, e[i] + e[j]), (-0.5 * d, e[i] - e[j]))


def _exact_trials(base: _Base, speed: bool) -> list[_Trial]:
    """The reference (or its held version), every row coefficient dropped or flipped, the entries a radius
    convention or a planet count touches, and the frame terms."""
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
            for r in base.radii.get(int(j), []) if len(nonzero) > 1 else []:
                for p in POWERS:
                    scaled = a.copy()
                    scaled[j] *= r**p
                    trials.append(_Trial(Candidate(f"{prefix}: {coordinate} coefficient times r^{p:+d} "
                                                   f"(r = {r:.6g} m)", "radius power", row=name,
                                                   coordinate=coordinate, factor=r**p), ((k, scaled), (-k, a))))
    trials += _entry_trials(base)
    if speed:
        trials.append(_Trial(Candidate("gyroscopic terms missing", "gyroscopic"), gyroscopic=False))
        trials.append(_Trial(Candidate("centripetal terms missing", "centripetal"), frame=np.zeros_like(base.Kc)))
        if np.any(base.Kc_textbook != base.Kc):
            trials.append(_Trial(Candidate("centripetal stiffness without the rigid-turn correction (Lin & Parker "
                                           "1999's softening -m Omega^2 alone)", "rigid-turn correction"),
                                 frame=base.Kc_textbook))
    return trials


def _entry_trials(base: _Base) -> list[_Trial]:
    """Stiffness entries changed as a formulation's slips change them: an entry with a rotation coordinate times
    r^p of that member's radius (u = r theta: K_theta = D K_u D, D = diag(r) on the rotations; e.g. N r_c k for
    the carrier's N r_c^2 k), and a stage's central entries with the planets' share written for n' planets where
    the train has N (n' times one planet's term, Lin & Parker 1999's sums over the planets)."""
    trials, K = [], base.K
    floor = COEFFICIENT_FLOOR * np.sqrt(np.abs(np.outer(np.diag(K), np.diag(K))))
    for i, j in zip(*np.nonzero(np.triu(np.abs(K) > floor))):
        tried = set()
        for c in dict.fromkeys((i, j)):
            for r in base.radii.get(int(c), []):
                for p in POWERS:
                    if (factor := round(r**p, 12)) in tried:
                        continue
                    tried.add(factor)
                    term = (f"stiffness entry ({base.labels[i]}, {base.labels[j]}) times r^{p:+d} of "
                            f"{base.member[c].id} (r = {r:.6g} m)")
                    trials.append(_Trial(Candidate(term, "radius power", coordinates=[base.labels[i], base.labels[j]],
                                                   member=base.member[c].id, factor=r**p),
                                         _entry(base, i, j, K[i, j] * (r**p - 1.0))))
    for N, P, central in base.planet_sums:
        for a, i in enumerate(central):
            for j in central[a:]:
                if abs(P[i, j]) <= floor[i, j]:
                    continue
                for count in range(1, N + 2):
                    if count != N:
                        term = (f"stiffness entry ({base.labels[i]}, {base.labels[j]}): its sum over the planets "
                                f"written for {count} planets (the train has {N})")
                        trials.append(_Trial(Candidate(term, "planet count", coordinates=[base.labels[i],
                                                                                          base.labels[j]],
                                                       factor=count / N),
                                             _entry(base, i, j, P[i, j] * (count / N - 1.0))))
    return trials


def _fitted_trials(base: _Base, scorer: _Scorer) -> list[_Trial]:
    """Every row's stiffness, every spring the reference lacks (:meth:`_Base._springs`) and every member inertia
    times a factor fitted to the at-rest frequencies: the best of a grid, then Gauss-Newton steps in log factor
    while they move.  A row adds (factor - 1) k a a^T, an extra spring factor s v v^T."""
    vectors = [a for *_, a in base.rows] + [v for *_, v, _ in base.springs]
    B = np.array([base.Linv @ a for a in vectors]).reshape(-1, base.n)  # whitened rows
    k = np.array([row[2] for row in base.rows] + [s for *_, s in base.springs])
    offset = np.array([1.0] * len(base.rows) + [0.0] * len(base.springs))
    masks = np.array([mask for *_, mask in base.inertias]).reshape(-1, base.n)
    n_rows, n = len(B), len(B) + len(masks)

    def solve(p, idx, vectors):  # the families idx (rows first, then inertias) at log factors p
        row, inertia = idx < n_rows, idx >= n_rows
        r, i = idx[row], idx[inertia] - n_rows
        Kt = np.empty((len(idx), base.n, base.n))
        Kt[row] = base.Kt + ((np.exp(p[row]) - offset[r]) * k[r])[:, None, None] * B[r, :, None] * B[r, None, :]
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
    changes[len(base.rows):n_rows] = True  # an extra spring is a change at any stiffness
    for (prefix, name, k_row, a), q in zip(base.rows, best_p[:len(base.rows)]):
        factor = float(np.exp(q))
        trials.append(_Trial(Candidate(f"{prefix} stiffness x {factor:.4g}", "stiffness", row=name, factor=factor),
                             (((factor - 1.0) * k_row, a),), fitted=True))
    for (term, coordinates, v, scale), q in zip(base.springs, best_p[len(base.rows):n_rows]):
        stiffness = float(np.exp(q) * scale)
        trials.append(_Trial(Candidate(f"{term}, stiffness {stiffness:.4g}", "extra spring",
                                       coordinates=list(coordinates), stiffness=stiffness),
                             ((stiffness, v),), fitted=True))
    for (term, member, coordinates, mask), q in zip(base.inertias, best_p[n_rows:]):
        factor = float(np.exp(q))
        named = [f" ({why})" for value, why in base.conventions.get(member, {}).items()
                 if coordinates == [f"{member}.{ROTATION}"] and abs(factor / value - 1.0) <= CONVENTION]
        trials.append(_Trial(Candidate(f"{term} x {factor:.4g}{''.join(named[:1])}", "inertia", member=member,
                                       coordinates=list(coordinates), factor=factor),
                             scale=np.where(mask, math.sqrt(factor), 1.0), fitted=True))
    return [t for t, change in zip(trials, changes) if change]


def _classes(trials: list[_Trial], reference: _Trial) -> list[list[_Trial]]:
    """The trials in classes this evidence cannot tell apart (scores and every compared frequency the same to
    EQUIVALENCE), best first; the reference heads its own class, whatever looks like it joins it, and an exact
    change heads a class before a fitted one (a fitted spring can match an exact entry's change)."""
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
    return sorted((sorted(c, key=lambda t: t.fitted) for c in classes), key=lambda c: c[0].candidate.score)


def _at_speed(base: _Base, trial: _Trial, evidence: np.ndarray) -> None:
    """Add the at-speed part to a trial's score."""
    trial.speed = base.speed_frequencies(trial)[:len(evidence)]
    trial.candidate.parts["speed"] = float(_errors(trial.speed, evidence))
    trial.candidate.score += trial.candidate.parts["speed"]


def _best_pair(base: _Base, scorer: _Scorer, trials: list[_Trial], partial: np.ndarray,
               speed: np.ndarray | None) -> tuple[_Trial | None, int]:
    """The best pair of exact changes (a fitted factor, fitted alone, would be wrong in a pair): each of the
    :data:`PAIR_POOL` best exact changes at rest (a planet's row and its look-alikes on the other planets among
    them, which frequencies alone cannot tell apart while the pair can) with every other exact change, scored
    exactly, at speed for the :data:`PAIR_POOL` best at rest; and how many pairs were scored."""
    exact = [i for i in np.argsort(partial, kind="stable")
             if not trials[i].fitted and trials[i].candidate.kind not in ("no mistake", "held coordinates")]
    first = [trials[i] for i in exact[:PAIR_POOL]]
    pairs = [_Trial(Candidate(f"two changes: {a.candidate.term}; and {b.candidate.term}", "pair",
                              pair=[replace(a.candidate, equivalents=[]), replace(b.candidate, equivalents=[])]),
                    a.outer + b.outer, gyroscopic=a.gyroscopic and b.gyroscopic,
                    frame=a.frame if a.frame is not None else b.frame)
             for a in first for b in (trials[i] for i in exact) if b is not a and (a.frame is None or b.frame is None)]
    if not pairs:
        return None, 0
    changed = [base.changed(t) for t in pairs]
    rest, shapes, f = scorer.score(np.array([c[0] for c in changed]), np.array([c[1] for c in changed]))
    for t, r, sh, fi in zip(pairs, rest, shapes, f):
        t.rest = fi
        t.candidate.parts = {"rest": float(r)} | ({"shapes": float(sh)} if scorer.E is not None else {})
        t.candidate.score = float(r + sh)
    pairs = sorted(pairs, key=lambda t: t.candidate.score)[:PAIR_POOL]
    if speed is not None:
        for t in pairs:
            _at_speed(base, t, speed)
    return min(pairs, key=lambda t: t.candidate.score), len(changed)


def diagnose(model: LumpedModel, evidence: Evidence, top: int = 3) -> Diagnosis:
    """Rank one-term changes of the reference ``model`` by how well they explain ``evidence``: the ``top``
    classes of look-alike candidates, best first (the reference first when it agrees; a pair of exact changes
    first when no one change explains the evidence and the pair scores below :data:`PAIR_MARGIN` times the best)."""
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
        _at_speed(base, reference, speed_evidence)
        evaluated = [reference]
        for i in np.argsort(partial, kind="stable"):
            if trials[i] is reference:
                continue
            certain = [t for t in evaluated if t.candidate.score <= partial[i]]  # no trial left scores less
            if len(certain) >= top and sum(c[0].candidate.score <= partial[i]
                                           for c in _classes(certain, reference)) >= top:
                break
            _at_speed(base, trials[i], speed_evidence)
            evaluated.append(trials[i])
        ranked = _classes(evaluated, reference)
    if not base.held and reference.candidate.score <= AGREEMENT:  # the reference first when it agrees
        ranked.sort(key=lambda c: c[0] is not reference)
    candidates = [replace(c[0].candidate, equivalents=[] if c[0] is reference else [t.candidate for t in c[1:]])
                  for c in ranked[:top]]  # what looks like the reference is a change this evidence cannot see
    pairs = 0
    if candidates[0].score > AGREEMENT:
        pair, pairs = _best_pair(base, scorer, trials, partial, speed_evidence)
        if pair is not None and pair.candidate.score < PAIR_MARGIN * candidates[0].score:
            candidates = [pair.candidate] + candidates[:top - 1]
    counts = {"rest": scorer.m, "shapes": 0 if scorer.E is None else scorer.m,
              "speed": 0 if speed_evidence is None else len(speed_evidence)}
    rigid = int(np.sum(scorer.f**2 <= RIGID_TOLERANCE * np.max(scorer.f) ** 2))
    return Diagnosis(model.spec.name, candidates, None if base.held else reference.candidate.score, base.held,
                     counts, len(trials), rigid_modes={"evidence": rigid, "reference": base.rigid}, pairs=pairs)


def diagnose_side(model: LumpedModel, side, modal=None, top: int = 3) -> Diagnosis:
    """The diagnosis of a user's model as the cross-check holds it (a :class:`~gearcheck.shared.side.Side`)
    against the reference ``model``: its frequencies, its shapes and its frequencies at the operating speed where
    it has them.  A model given as matrices over the train's members (its extra coordinates aside) is compared
    with the reference reduced to its coordinates as it declares, held or condensed
    (:func:`~gearcheck.compare.engine.reduction.reduction_basis`, then :func:`constrained`), so a torsional
    model is held to the reference with its translations tied as its map ties them.  ``modal``: the side's modes
    when already computed."""
    modal = side.modes() if modal is None else modal
    try:
        at_speed = side.modes_at_speed(model.spec.operating.input_speed).frequencies
    except UnsupportedError:
        at_speed = None
    linear = side.linear
    own = [] if linear is None else [i for i, c in enumerate(linear.coordinates) if c not in linear.extra]
    coordinates = [linear.coordinates[i] for i in own]
    if own and all("." in c and c.rsplit(".", 1)[0] in model.spec.members for c in coordinates):
        T, mapped = linear.to_physical(model.dofs.labels())
        basis = reduction_basis(model.K_mean, T[:, own], mapped, linear.reduction)
        reduced = constrained(model, coordinates, basis)
        diagnosis = diagnose(reduced, Evidence(coordinates, modal.frequencies, modal.shapes[own],
                                               linear.M[np.ix_(own, own)], at_speed), top)
        if len(coordinates) < model.n:
            diagnosis.reduced_to, diagnosis.reduction = len(coordinates), linear.reduction
        return diagnosis
    try:
        labels, mass, shapes = side.physical_modes(modal)
    except UnsupportedError:  # a recording without mode shapes
        labels, mass, shapes = model.dofs.labels(), None, None
    return diagnose(model, Evidence(labels, modal.frequencies, shapes, mass, at_speed), top)
