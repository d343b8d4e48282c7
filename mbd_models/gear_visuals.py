"""Visual meshes of the involute gears of a train (and of an RV reducer's cycloid discs: their exact profile,
:func:`gearcheck.train.cycloid.disc_profile`), for MuJoCo's viewer and offscreen renders.

Visual only: the geoms that carry these meshes are contact-free (contype = conaffinity = 0) and the
bodies' mass and inertia come from their explicit ``<inertial>`` (the compiler has
``inertiafromgeom="false"``), so the twin's dynamics do not see them.

The transverse section of every tooth is the involute of the base circle r_b: a flank point at radius
r lies at the polar angle inv(alpha_r) = tan(alpha_r) - alpha_r from where the involute leaves the base
circle, alpha_r = arccos(r_b / r) (Litvin & Fuentes 2004, Gear Geometry and Applied Theory, ch. 10).
With the arc tooth thickness on the base circle s_b (ISO 21771; it carries the profile shift) the
flank's half-angle from the tooth centre line is psi_b - inv(alpha_r), psi_b = s_b / (2 r_b).  An
internal gear's space is such an external tooth: its own teeth (the metal between spaces) point inward.
Below the base circle the flank runs radially to the root circle.  Tip relief C_a over the roll length
L_a (distance along the line of action from the tip) is the flank turned by C_a ((rho - rho_s)/L_a)^p / r_b
into the tooth: exact as a normal displacement of an involute (a rotation by d/r_b moves it d along its
normal).  A helical gear is the section extruded in slices, each turned by z tan(beta) / r (r the
reference radius, beta signed), which makes a mating pair's helices coincide on the line of centres.

Phasing: the first central gear of a stage sits at angle 0; each gear that meshes with a placed one is
turned so that a tooth of one fills a space of the other where the line of centres crosses their
operating pitch circles (arcs on the two pitch circles match tooth for tooth, so this holds for any
profile shifts: a backlash-free pair's tooth fills the mate's space there).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from gearcheck.train.cycloid import CycloidGeometry, disc_profile
from gearcheck.train.geometry import Gear, base_tooth_thickness
from gearcheck.train.spec import TrainSpec

FLANK_POINTS = 4  # per flank, evenly spaced in roll length
HELIX_SLICES = 4  # extrusion slices of a helical gear
RIM = 2.0  # ring rim outside the root circle, in modules
UNIT = 1e-6  # vertex coordinates are written in integer micrometres (mesh scale)
DISC_POINTS = 8  # profile points per lobe of a cycloid disc
IDEALISED_POINTS = 96  # points on the drawn circle of an idealised gear (no teeth)
IDEALISED_WIDTH = 0.02  # m: how wide an idealised gear that gives no face width is drawn
IDEALISED_MODULE = 0.02  # of its pitch radius: the size of an idealised gear's rim and marker


def face_width(gear: Gear) -> float:
    """The width the gear is drawn with: its face width, or ``IDEALISED_WIDTH`` for an idealised gear without."""
    return gear.face_width or IDEALISED_WIDTH


def module(gear: Gear, normal: bool = False) -> float:
    """What rims and markers are sized by: the gear's (normal) module, or ``IDEALISED_MODULE`` of an idealised
    gear's pitch radius."""
    if gear.idealised:
        return IDEALISED_MODULE * gear.pitch_radius
    return gear.normal_module if normal else gear.module


def relief(gear: Gear, r: np.ndarray) -> np.ndarray:
    """Tip relief (m, normal to the flank) at radius ``r``: C_a ((rho - rho_s) / L_a)^p inside the relief zone."""
    r = np.asarray(r, dtype=float)
    if not gear.relief_amount or not gear.relief_length:
        return np.zeros_like(r)
    roll = np.sqrt(np.maximum(r**2 - gear.base_radius**2, 0.0))
    tip = math.sqrt(gear.tip_radius**2 - gear.base_radius**2)
    into = (roll - (tip - gear.relief_length)) if not gear.internal else ((tip + gear.relief_length) - roll)
    return gear.relief_amount * np.clip(into / gear.relief_length, 0.0, None) ** gear.relief_power


def half_angle(gear: Gear, r: np.ndarray) -> np.ndarray:
    """Half-angle (rad) of a tooth at radius r >= r_b about its centre line: psi_b - inv(alpha_r) for an
    external gear, pi/z - (psi_b - inv(alpha_r)) for an internal one (whose space is the involute tooth),
    less the tip relief turned into the tooth."""
    r = np.asarray(r, dtype=float)
    alpha = np.arccos(np.clip(gear.base_radius / r, -1.0, 1.0))
    space = base_tooth_thickness(gear) / (2 * gear.base_radius) - (np.tan(alpha) - alpha)
    tooth = math.pi / gear.teeth - space if gear.internal else space
    return tooth - relief(gear, r) / gear.base_radius


def tooth_outline(gear: Gear, flank_points: int = FLANK_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Polar points (r, phi) of one tooth pitch centred on phi = 0, phi increasing from -pi/z (the middle of
    the space on the root circle) to just before +pi/z: root, flank, tip centre, flank."""
    rb, ra, rf = gear.base_radius, gear.tip_radius, gear.root_radius
    lo = max(rb, min(ra, rf))
    hi = max(ra, rf)
    roll = np.linspace(math.sqrt(lo**2 - rb**2), math.sqrt(hi**2 - rb**2), flank_points)
    flank = np.sqrt(rb**2 + roll**2)  # base/root side to the far end
    if gear.internal:
        flank = flank[::-1]  # from the root (outer) to the tip (inner)
    rising = [(rf, -math.pi / gear.teeth)]
    if not gear.internal and rf < rb:
        rising.append((rf, -float(half_angle(gear, rb))))  # radial below the base circle
    rising += [(r, -a) for r, a in zip(flank, half_angle(gear, flank))]
    falling = [(r, -phi) for r, phi in reversed(rising[1:])]
    points = rising + [(ra, 0.0)] + falling
    r, phi = np.array(points).T
    return r, phi


def section(gear: Gear, flank_points: int = FLANK_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """The whole transverse boundary of the teeth (r, phi), tooth k centred on 2 pi k / z, phi increasing; an
    idealised gear's pitch circle in ``IDEALISED_POINTS`` points."""
    if gear.idealised:
        phi = np.arange(IDEALISED_POINTS) * 2 * math.pi / IDEALISED_POINTS
        return np.full(IDEALISED_POINTS, gear.pitch_radius), phi
    r, phi = tooth_outline(gear, flank_points)
    pitch = 2 * math.pi / gear.teeth
    return np.tile(r, gear.teeth), np.concatenate([phi + k * pitch for k in range(gear.teeth)])


def _ring_cap(teeth: int, per_tooth: int) -> list[tuple[int, int, int]]:
    """Triangles (normal +z) of a ring's end face: each tooth pitch of the inner boundary (indices from 0) fanned
    from the rim point (index n + k) at its tooth's centre, and one triangle to the next rim point."""
    n = teeth * per_tooth
    tris = []
    for k in range(teeth):
        rim, start = n + k, k * per_tooth
        tris += [(rim, (c + 1) % n, c) for c in range(start, start + per_tooth)]
        tris.append((rim, n + (k + 1) % teeth, (start + per_tooth) % n))
    return tris


def gear_mesh(gear: Gear, flank_points: int = FLANK_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Closed, outward-oriented triangle mesh of the gear (vertices in m, faces), centred on z = 0.

    An external gear is a solid toothed disc (end faces fanned from the axis: the section is star-shaped about
    it); an internal one an annulus (rim ``RIM`` modules outside the root circle) with its teeth on the inside.  A
    helical gear is extruded in ``HELIX_SLICES`` twisted slices.
    """
    r, phi = section(gear, flank_points)
    n = len(r)
    slices = HELIX_SLICES if gear.helix_angle else 1
    width = face_width(gear)
    zs = np.linspace(-0.5 * width, 0.5 * width, slices + 1)
    twist = zs * math.tan(gear.helix_angle) / gear.pitch_radius
    teeth = gear.teeth or IDEALISED_POINTS  # an idealised ring's rim: a point beside each of its circle's
    if gear.internal:
        outer_phi = np.arange(teeth) * 2 * math.pi / teeth  # tooth centres
        rings = [(r, phi), (np.full(len(outer_phi), gear.root_radius + RIM * module(gear, normal=True)), outer_phi)]
    else:
        rings = [(r, phi)]
    per_slice = sum(len(x) for x, _ in rings)
    vertices = [np.column_stack([rr * np.cos(pp + t), rr * np.sin(pp + t), np.full(len(rr), z)])
                for z, t in zip(zs, twist) for rr, pp in rings]
    faces = []

    def wall(start: int, count: int, outward: bool) -> None:
        for s in range(slices):
            lo, hi = start + s * per_slice, start + (s + 1) * per_slice
            for i in range(count):
                k = (i + 1) % count
                quad = [(lo + i, lo + k, hi + k), (lo + i, hi + k, hi + i)]
                faces.extend(quad if outward else [(a, c, b) for a, b, c in quad])

    wall(0, n, not gear.internal)
    top = slices * per_slice
    if gear.internal:
        wall(n, len(rings[1][0]), True)
        for a, b, c in _ring_cap(teeth, n // teeth):  # top (+z) and bottom (-z) caps
            faces += [(top + a, top + b, top + c), (a, c, b)]
    else:  # fans to a centre vertex on each end
        centre = len(zs) * per_slice
        vertices.append(np.array([[0.0, 0.0, zs[0]], [0.0, 0.0, zs[-1]]]))
        for i in range(n):
            k = (i + 1) % n
            faces += [(top + i, top + k, centre + 1), (i, centre, k)]
    return np.vstack(vertices), np.array(faces, dtype=int)


def phases(spec: TrainSpec) -> dict[tuple[str, str], float]:
    """Rotation (rad) of every gear (member id, gear name) in its body frame so that mating teeth mesh:
    a tooth centre of one gear faces a space centre of the other on the line of centres."""
    def key(member_id: str, gear: Gear) -> tuple[str, str]:
        return member_id, next(name for name, g in spec.members[member_id].gears.items() if g == gear)

    placed: dict[tuple[str, str], float] = {}
    todo = list(spec.meshes)
    while todo:
        for mesh in todo:
            c, p = key(mesh.central, mesh.central_gear), key(mesh.planet, mesh.planet_gear)
            if c in placed or p in placed:
                break
        else:
            mesh = todo[0]
            c, p = key(mesh.central, mesh.central_gear), key(mesh.planet, mesh.planet_gear)
            placed[c] = 0.0
        todo.remove(mesh)
        if mesh.central_gear.idealised:  # no teeth to mesh: every gear at its own angle 0
            placed.setdefault(c, 0.0)
            placed.setdefault(p, 0.0)
            continue
        psi = spec.members[mesh.planet].angle
        zc, zp = mesh.central_gear.teeth, mesh.planet_gear.teeth
        internal = mesh.internal
        if c in placed and p in placed:
            continue
        if c in placed:  # fraction of a pitch from the central gear's tooth (ring: space) centre to the line
            u = (zc * (psi - placed[c] - (math.pi / zc if internal else 0.0)) / (2 * math.pi)) % 1.0
            placed[p] = psi - 2 * math.pi * u / zp if internal else psi + math.pi + (2 * math.pi * u + math.pi) / zp
        else:
            toward = psi if internal else psi + math.pi  # the planet's side facing the central gear
            u = (zp * (toward - placed[p]) / (2 * math.pi)) % 1.0
            placed[c] = (psi - (2 * math.pi * u + math.pi) / zc) if internal else psi + (2 * math.pi * u + math.pi) / zc
    return placed


def disc_mesh(geometry: CycloidGeometry, points_per_lobe: int = DISC_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """Closed, outward-oriented triangle mesh of a cycloid disc (its exact profile, star-shaped about its centre,
    extruded over its thickness and fanned from the axis on each end), centred on z = 0; no bores."""
    x, y = disc_profile(geometry, points_per_lobe=points_per_lobe).T
    n, half = len(x), 0.5 * geometry.contact_length
    vertices = np.vstack([np.column_stack([x, y, np.full(n, z)]) for z in (-half, half)] + [[[0.0, 0.0, -half],
                                                                                             [0.0, 0.0, half]]])
    faces = []
    for i in range(n):
        k = (i + 1) % n
        faces += [(i, k, n + k), (i, n + k, n + i), (n + i, n + k, 2 * n + 1), (i, 2 * n, k)]
    return vertices, np.array(faces, dtype=int)


def disc_asset(name: str, geometry: CycloidGeometry) -> str:
    """``<mesh>`` element of a cycloid disc (:func:`disc_mesh`)."""
    return _mesh_element(name, *disc_mesh(geometry))


@functools.lru_cache(maxsize=256)
def mesh_asset(name: str, gear: Gear) -> str:
    """``<mesh>`` element of ``gear`` with inline vertices (integer micrometres, scaled) and faces (kept: the twins
    of one train at many speeds, a sweep's, draw the same gears; 20 ms each on hub-drive)."""
    return _mesh_element(name, *gear_mesh(gear))


def _mesh_element(name: str, vertices: np.ndarray, faces: np.ndarray) -> str:
    v = " ".join(str(int(x)) for x in np.rint(vertices / UNIT).ravel())
    f = " ".join(str(int(x)) for x in faces.ravel())
    return f'<mesh name="{name}" scale="{UNIT!r} {UNIT!r} {UNIT!r}" vertex="{v}" face="{f}"/>'
