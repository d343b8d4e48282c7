"""The works gearcheck builds on, one table of full references.

Train files name the works they come from (``train.references = ["li2026"]``), models name the
works their equations come from (``references`` of a solver side or a mesh stiffness model), and
every cross-check report lists the keys its run used with their full citations.  Docstrings cite a
work as authors and year, which is its key here.
"""

from __future__ import annotations

from dataclasses import dataclass

from gearcheck.shared.errors import did_you_mean


@dataclass(frozen=True)
class Reference:
    authors: str
    year: int
    title: str
    where: str  # journal, volume, pages; or standard; or publisher
    doi: str = ""

    @property
    def citation(self) -> str:
        doi = f", doi:{self.doi}" if self.doi else ""
        return f"{self.authors} ({self.year}). {self.title}. {self.where}{doi}."


REFERENCES: dict[str, Reference] = {
    "lin-parker-1999": Reference(
        "Lin J., Parker R. G.", 1999, "Analytical characterization of the unique properties of planetary gear "
        "free vibration", "Journal of Vibration and Acoustics 121(3), 316-321"),
    "lin-parker-2000": Reference(
        "Lin J., Parker R. G.", 2000, "Structured vibration characteristics of planetary gears with unequally "
        "spaced planets", "Journal of Sound and Vibration 233(5), 921-928"),
    "parker-2000": Reference(
        "Parker R. G.", 2000, "A physical explanation for the effectiveness of planet phasing to suppress "
        "planetary gear vibration", "Journal of Sound and Vibration 236(4), 561-573"),
    "lin-parker-2002": Reference(
        "Lin J., Parker R. G.", 2002, "Planetary gear parametric instability caused by mesh stiffness variation",
        "Journal of Sound and Vibration 249(1), 129-145"),
    "parker-lin-2004": Reference(
        "Parker R. G., Lin J.", 2004, "Mesh phasing relationships in planetary and epicyclic gears",
        "Journal of Mechanical Design 126(2), 365-370"),
    "kiracofe-parker-2007": Reference(
        "Kiracofe D. R., Parker R. G.", 2007, "Structured vibration modes of general compound planetary gear "
        "systems", "Journal of Vibration and Acoustics 129(1), 1-16"),
    "cooley-parker-2012": Reference(
        "Cooley C. G., Parker R. G.", 2012, "Vibration properties of high-speed planetary gears with gyroscopic "
        "effects", "Journal of Vibration and Acoustics 134(6), 061014"),
    "eritenel-parker-2009": Reference(
        "Eritenel T., Parker R. G.", 2009, "Modal properties of three-dimensional helical planetary gears",
        "Journal of Sound and Vibration 325(1-2), 397-420"),
    "maatar-velex-1996": Reference(
        "Maatar M., Velex P.", 1996, "An analytical expression for the time-varying contact length in perfect "
        "cylindrical gears: some possible applications in gear dynamics", "Journal of Mechanical Design 118(4), "
        "586-589"),
    "mo-2024": Reference(
        "Mo S., Liu Z., Luo B., Cen G., Xu J.", 2024, "Dynamic characteristics of planetary gear transmission "
        "system with tooth profile modification", "Journal of Vibration Engineering 37(2), 191-199 (in Chinese)"),
    "weber-1949": Reference(
        "Weber C.", 1949, "The deformation of loaded gears and the effect on their load-carrying capacity",
        "Sponsored Research (Germany), British Department of Scientific and Industrial Research, Report No. 3"),
    "cornell-1981": Reference(
        "Cornell R. W.", 1981, "Compliance and stress sensitivity of spur gear teeth",
        "Journal of Mechanical Design 103(2), 447-459"),
    "sainsot-2004": Reference(
        "Sainsot P., Velex P., Duverger O.", 2004, "Contribution of gear body to tooth deflections, a new "
        "bidimensional analytical formula", "Journal of Mechanical Design 126(4), 748-752"),
    "tian-2004": Reference(
        "Tian X.", 2004, "Dynamic simulation for system response of gearbox including localized gear faults",
        "MSc thesis, University of Alberta, Edmonton"),
    "iso53": Reference(
        "ISO", 1998, "ISO 53: Cylindrical gears for general and heavy engineering, standard basic rack tooth "
        "profile", "International Organization for Standardization, Geneva"),
    "iso6336-1": Reference(
        "ISO", 2006, "ISO 6336-1: Calculation of load capacity of spur and helical gears, Part 1: Basic "
        "principles, introduction and general influence factors", "International Organization for "
        "Standardization, Geneva"),
    "iso21771": Reference(
        "ISO", 2007, "ISO 21771: Gears, cylindrical involute gears and gear pairs, concepts and geometry",
        "International Organization for Standardization, Geneva"),
    "todorov-2012": Reference(
        "Todorov E., Erez T., Tassa Y.", 2012, "MuJoCo: a physics engine for model-based control",
        "IEEE/RSJ International Conference on Intelligent Robots and Systems, 5026-5033",
        "10.1109/IROS.2012.6386109"),
    "li2026": Reference(
        "Li F., Du X., Jiao H., Zhang J., Fu Q.", 2026, "Dynamic modeling of planetary gear reducer in "
        "high-torque hub drive system", "Symmetry 18(3), 429", "10.3390/sym18030429"),
    "matejic2021": Reference(
        "Matejic M. S., Blagojevic M. Z., Matejic M. M.", 2021, "Dynamic behaviour of a planetary reducer with "
        "double planet gears", "Mechanical Sciences 12, 983-991", "10.5194/ms-12-983-2021"),
    "yang2018": Reference(
        "Yang Y.-H., Chen C., Wang S.-Y.", 2018, "Response sensitivity to design parameters of RV reducer",
        "Chinese Journal of Mechanical Engineering 31", "10.1186/s10033-018-0249-y"),
    "mo2024": Reference(
        "Mo S., Liu Z., Luo B., Cen G., Xu J.", 2024, "Dynamic characteristics of planetary gear transmission "
        "system with tooth profile modification", "Journal of Vibration Engineering 37(2), 191-199",
        "10.16385/j.cnki.issn.1004-4523.2024.02.001"),
}


def unknown(key: str) -> str:
    """The message for a key that is not in :data:`REFERENCES`, with a did-you-mean."""
    return f"no reference {key!r} in gearcheck's table{did_you_mean(key, REFERENCES, 'known')}"


def cite(keys) -> list[dict]:
    """``[{"key", "citation"}]`` for ``keys`` in order of first appearance, each once."""
    return [{"key": key, "citation": REFERENCES[key].citation} for key in dict.fromkeys(keys)]
