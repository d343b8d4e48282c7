"""Train-file fields that let published systems be written as they are printed: an input torque, masses
and inertias from a density, a stated carrier radius."""

import math
import re

import pytest

from gearcheck.train.variants import edited
from gearcheck.shared.errors import TrainFileError

STEEL = 7850.0


def test_an_input_torque_loads_the_output_by_the_ratio():
    """demo-3p's ratio is 1 + 62/22: 392.857 N·m at the sun is its 1500 N·m at the carrier."""
    spec = edited("demo-3p", [(r"^output_torque = 1500.0 .*$", "input_torque = 392.857142857143")], "input torque")
    assert spec.operating.input_torque == 392.857142857143
    assert spec.operating.output_torque == pytest.approx(392.857142857143 * (1 + 62 / 22), rel=1e-12)
    with pytest.raises(TrainFileError, match="operating.input_torque: give input_torque or output_torque"):
        edited("demo-3p", [(r"^output_torque = 1500.0 .*$", "output_torque = 1.0\ninput_torque = 3.0")], "both")


def annulus(outer, inner, width):
    mass = STEEL * math.pi * (outer**2 - inner**2) * width
    return mass, 0.5 * mass * (outer**2 + inner**2)


DENSITY = [(r"^mass = 0.9757 .*\ninertia = 5.802e-4", "density = 7850.0\ninner_radius_mm = 10.0"),
           (r"^mass = 3.404 .*\ninertia = 3.532e-2", "density = 7850.0\nouter_radius_mm = 110.0"),
           (r"^mass = 5.050 .*\ninertia = 1.925e-2",
            "density = 7850.0\nouter_radius_mm = 85.0\ninner_radius_mm = 20.0\nthickness_mm = 30.0"),
           (r"^mass = 0.7458 .*\ninertia = 3.893e-4", "density = 7850.0\ninner_radius_mm = 12.0")]


def test_masses_and_inertias_from_a_density():
    """Gears are annuli from their bore to their pitch circle over their face width (40 mm), the ring from
    its pitch circle out, the carrier from its inner to its outer radius over its plates' thickness: the
    closed forms, and demo-3p's hand-computed values to their four printed digits."""
    spec = edited("demo-3p", DENSITY, "density")
    expected = {"stage1.sun": annulus(0.033, 0.010, 0.040), "stage1.ring": annulus(0.110, 0.093, 0.040),
                "stage1.carrier": annulus(0.085, 0.020, 0.030), "stage1.planet1": annulus(0.030, 0.012, 0.040)}
    printed = edited("demo-3p", [], "as printed")
    for mid, (mass, inertia) in expected.items():
        member = spec.members[mid]
        assert member.mass == pytest.approx(mass, rel=1e-12) and member.inertia == pytest.approx(inertia, rel=1e-12)
        assert member.mass == pytest.approx(printed.members[mid].mass, rel=2e-4)
        # the sun's printed 5.802e-4 is 5.800e-4
        assert member.inertia == pytest.approx(printed.members[mid].inertia, rel=5e-4)


def test_a_given_mass_wins_over_the_density():
    """The inertia then takes the stated mass at the annulus's radius of gyration."""
    spec = edited("demo-3p", [(r"^mass = 0.9757 .*\ninertia = 5.802e-4", "density = 7850.0\nmass = 1.5")], "both")
    sun = spec.members["stage1.sun"]
    assert sun.mass == 1.5 and sun.inertia == pytest.approx(1.5 * 0.033**2 / 2, rel=1e-12)


@pytest.mark.parametrize("edit, message", [
    ((r"^mass = 0.9757 .*\ninertia = 5.802e-4", "inertia = 5.802e-4"),
     "stages[0].sun.mass: missing: give mass, or a density"),
    ((r"^mass = 3.404 .*\ninertia = 3.532e-2", "density = 7850.0"),
     "stages[0].ring.outer_radius_mm: a ring's mass from its density needs its outer radius"),
    ((r"^mass = 5.050 .*\ninertia = 1.925e-2", "density = 7850.0\nouter_radius_mm = 85.0"),
     "stages[0].carrier.thickness_mm: a carrier's mass from its density needs"),
    ((r"^mass = 0.7458 .*\ninertia = 3.893e-4", "density = 7850.0\ninner_radius_mm = 40.0"),
     "stages[0].planet.inner_radius_mm: must be less than the outer radius 30 mm"),
])
def test_incomplete_density_data_is_refused_by_field(edit, message):
    with pytest.raises(TrainFileError, match=re.escape(message)):
        edited("demo-3p", [edit], "bad")


def test_a_stated_carrier_radius_must_be_where_the_gears_mesh():
    """demo-3p's operating centre distance is m (z_s + z_p)/2 = 3 (22 + 20)/2 = 63 mm."""
    ok = edited("demo-3p", [(r"^planets = 3", "planets = 3\ncarrier_radius_mm = 63.0")], "stated")
    assert ok.stages[0].carrier_radius == pytest.approx(0.063, abs=1e-12)
    with pytest.raises(TrainFileError, match="carrier_radius_mm: 63.1 mm, but the gears mesh at an operating "
                                             "centre distance of 63 mm"):
        edited("demo-3p", [(r"^planets = 3", "planets = 3\ncarrier_radius_mm = 63.1")], "off")
