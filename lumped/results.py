"""The time-response result shared by both solvers: one object, named access, pandas export.

Member accelerations are given three ways:

* ``coordinate``: the second derivatives of the model's own coordinates (for the lumped
  model, rotating-frame components);
* ``carrier``: the absolute (inertial) acceleration of the member's centre, resolved
  along the axes of its stage's carrier frame (for planets: radial, tangential);
* ``world``: the same vector resolved along the fixed x, y axes, as a housing-mounted
  accelerometer sees it.

Angular accelerations are absolute in every frame (planar motion).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
import pandas as pd


@dataclass
class TimeResult:
    """Time series of one run.  Arrays have time along axis 0."""

    train: str
    solver: str
    t: np.ndarray
    members: list[str]
    acc_carrier: np.ndarray  # (n_t, n_members, 3): inertial acceleration in carrier axes, and angular
    carrier_angle: np.ndarray  # (n_t, n_members): angle of each member's carrier frame (world = R(angle) carrier)
    mesh_ids: list[str]
    mesh_deflection: np.ndarray  # (n_t, n_mesh) m: DTE
    mesh_force: np.ndarray  # (n_t, n_mesh) N
    mesh_stiffness: np.ndarray  # (n_t, n_mesh) N/m
    static_mesh_force: np.ndarray  # (n_mesh,) N
    bearing_names: list[str] = field(default_factory=list)
    bearing_force: np.ndarray | None = None  # (n_t, n_bearing) N
    settle_time: float = 0.0
    info: dict = field(default_factory=dict)  # solver settings, wall time, step counts
    raw: dict = field(default_factory=dict)  # solver-specific extra series (coordinates, sensors)

    @property
    def steady(self) -> np.ndarray:
        return self.t >= self.settle_time

    def member_index(self, member: str) -> int:
        return self.members.index(member)

    def acceleration(self, member: str, frame: str = "world") -> pd.DataFrame:
        """Acceleration of ``member``'s centre: columns ax, ay (m/s^2) and alpha (rad/s^2)."""
        a = self.acc_carrier[:, self.member_index(member), :]
        if frame == "world":
            ang = self.carrier_angle[:, self.member_index(member)]
            c, s = np.cos(ang), np.sin(ang)
            ax, ay = c * a[:, 0] - s * a[:, 1], s * a[:, 0] + c * a[:, 1]
        elif frame == "carrier":
            ax, ay = a[:, 0], a[:, 1]
        else:
            raise ValueError(f"frame must be 'world' or 'carrier', not {frame!r}")
        return pd.DataFrame({"t": self.t, "ax": ax, "ay": ay, "alpha": a[:, 2]})

    @property
    def dynamic_factor(self) -> np.ndarray:
        """Kv = F / F_static per mesh."""
        return self.mesh_force / self.static_mesh_force

    def to_dataframe(self, frame: str = "world") -> pd.DataFrame:
        columns = {"t": self.t}
        for m in self.members:
            acc = self.acceleration(m, frame)
            for c in ("ax", "ay", "alpha"):
                columns[f"{m}.{c}"] = acc[c].to_numpy()
        for j, mid in enumerate(self.mesh_ids):
            columns[f"{mid}.dte"] = self.mesh_deflection[:, j]
            columns[f"{mid}.force"] = self.mesh_force[:, j]
            columns[f"{mid}.kv"] = self.dynamic_factor[:, j]
            columns[f"{mid}.stiffness"] = self.mesh_stiffness[:, j]
        for j, name in enumerate(self.bearing_names):
            columns[f"{name}.force"] = self.bearing_force[:, j]
        return pd.DataFrame(columns)

    def summary(self) -> dict:
        """Steady-state peak-to-peak and RMS of every exported series (JSON-ready, SI units)."""
        df = self.to_dataframe().loc[self.steady]
        stats = {}
        for col in df.columns[1:]:
            x = df[col].to_numpy()
            stats[col] = {"mean": float(np.mean(x)), "rms": float(np.sqrt(np.mean(x**2))),
                          "peak_to_peak": float(np.ptp(x)), "max_abs": float(np.max(np.abs(x)))}
        return {"train": self.train, "solver": self.solver, "settle_time_s": self.settle_time,
                "samples": int(self.steady.sum()), "info": self.info, "series": stats}

    def write(self, directory) -> list:
        """Write ``timeseries.csv`` (and ``raw.csv`` if any) and ``summary.json`` into ``directory``."""
        from pathlib import Path

        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        written = []
        path = out / "timeseries.csv"
        self.to_dataframe().to_csv(path, index=False, float_format="%.9g")
        written.append(path)
        if self.raw:
            raw = pd.DataFrame({"t": self.t, **{k: v for k, v in self.raw.items()}})
            path = out / "raw.csv"
            raw.to_csv(path, index=False, float_format="%.9g")
            written.append(path)
        path = out / "summary.json"
        path.write_text(json.dumps(self.summary(), indent=2, sort_keys=True) + "\n")
        written.append(path)
        return written
