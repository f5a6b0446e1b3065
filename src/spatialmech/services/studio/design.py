"""The studio as a design tool (issue 30, "Also build"): what a :class:`Desk` adds to one
:class:`~spatialmech.services.studio.session.Session` (``session.desk``), without HTTP.

* :meth:`Desk.snapshot` / :meth:`Desk.undo` / :meth:`Desk.restore`: keep the configuration (with
  the drivers, the branch, the trail and the driven path) and go back to it.
* :meth:`Desk.coupler_curve`: the path of a point fixed to the output link (given in the output
  link's frame, the model's length unit), over the whole traced circuit of a one-degree-of-freedom
  linkage, else over the current driver's range (a :meth:`sweep`).
* :meth:`Desk.sweep`: joint values, the transmission index and sigma_min against one driver's
  value, the driver moved by continuation from the current configuration to either end of its
  slider range (the other drivers held), stopping where the session's drive stops.  The session
  is put back where it was.
* :meth:`Desk.path_csv`: the driven path (the actuator values at the end of each drive) as the
  CSV that ``spatialmech validate MODEL --actuators-path FILE`` reads.

Values out are in the model's length unit and degrees (labelled), as the session's readout.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ConvergenceError, InputError
from ...kinematics.jacobian import complete_jacobian
from ...kinematics.position import freedom_values
from ...results import DriveStatus
from ...serialize import freedom_values_dict
from .posing import transmission_readout

if TYPE_CHECKING:
    from .session import Session

__all__ = ["MAX_SNAPSHOTS", "SWEEP_SAMPLES", "Desk"]

#: Snapshots kept (the oldest are dropped).
MAX_SNAPSHOTS = 50
#: Default number of driver values of a sweep (both directions together).
SWEEP_SAMPLES = 61
#: Session attributes a snapshot keeps (copied; the configurations are immutable).
_KEPT = ("mech", "config", "start_values", "history", "driven", "last_stop", "fk_branch", "fk_modes", "note")


def _rotation(session: Session, aid: str) -> bool:
    return session.mech.freedom(aid).freedom.kind != "P"


def _display(session: Session) -> list[float]:
    """The current actuator values in display units (degrees for rotations, the length unit)."""
    return [float(np.degrees(v)) if _rotation(session, a) else float(v)
            for a, v in zip(session.mech.actuators, session.actuator_values(), strict=True)]


def _vec3(v, name: str) -> np.ndarray:
    if not isinstance(v, (list, tuple)) or len(v) != 3:
        raise InputError(f"{name}: expected three numbers [x, y, z], got {v!r}")
    if any(isinstance(x, bool) or not isinstance(x, (int, float)) or not np.isfinite(x) for x in v):
        raise InputError(f"{name}: expected three finite numbers, got {v!r}")
    return np.array(v, dtype=float)


class Desk:
    """Snapshots, coupler curves, sweeps and the driven path of ``session`` (module docstring)."""

    def __init__(self, session: Session):
        self.session = session
        self.snapshots: list[tuple[str, dict]] = []

    # ------------------------------------------------------------------ snapshots and undo
    def _keep(self) -> dict:
        s = self.session
        return {k: copy.copy(getattr(s, k)) for k in _KEPT}

    def _put_back(self, kept: dict) -> None:
        for k, v in kept.items():
            setattr(self.session, k, copy.copy(v))

    def snapshot(self, label=None) -> list[dict]:
        """Keep the current configuration under ``label`` (default ``"snapshot N"``); the list."""
        if label is not None and not isinstance(label, str):
            raise InputError(f"label: expected text, got {label!r}")
        self.snapshots.append((label or f"snapshot {len(self.snapshots) + 1}", self._keep()))
        del self.snapshots[:-MAX_SNAPSHOTS]
        return self.listing()

    def listing(self) -> list[dict]:
        """The snapshots, oldest first: ``number`` (from 1), ``label`` and the actuator values."""
        s = self.session
        return [{"number": k + 1, "label": lab, **freedom_values_dict(
            kept["mech"], dict(zip(kept["mech"].actuators, s.actuator_values(kept["config"]), strict=True)), "actuators")}
            for k, (lab, kept) in enumerate(self.snapshots)]

    def restore(self, number) -> None:
        """Go back to snapshot ``number`` (from 1), keeping it."""
        if isinstance(number, bool) or not isinstance(number, int):
            raise InputError(f"number: expected a whole number, got {number!r}")
        if not 1 <= number <= len(self.snapshots):
            raise InputError(f"number: expected 1 to {len(self.snapshots)} (the snapshots), got {number}"
                             if self.snapshots else "number: no snapshot yet (take one first)")
        self._put_back(self.snapshots[number - 1][1])

    def undo(self) -> str:
        """Go back to the last snapshot and drop it (the one before is next); its label."""
        if not self.snapshots:
            raise InputError("undo: no snapshot to go back to (take one first)")
        label, kept = self.snapshots.pop()
        self._put_back(kept)
        return label

    # ------------------------------------------------------------------ the driven path
    def path_csv(self) -> str:
        """The actuator values at the start and at the end of each drive, one row each, as the CSV
        of ``validate --actuators-path`` (rotations in degrees, ``_deg``; slides in the length unit)."""
        s = self.session
        acts = list(s.mech.actuators)
        rot = [s.mech.freedom(a).freedom.kind != "P" for a in acts]
        head = ",".join(f"{a}_deg" if r else a for a, r in zip(acts, rot, strict=True))
        rows = [",".join(f"{np.degrees(v) if r else v:.12g}" for v, r in zip(vals, rot, strict=True)) for vals in s.driven]
        return "\n".join([f"# {s.mech.name}: the driven path of a studio session ({s.mech.length_unit}, deg)",
                          head, *rows]) + "\n"

    # ------------------------------------------------------------------ sweeps and coupler curves
    def _driver_index(self, driver) -> int:
        acts = list(self.session.mech.actuators)
        if driver is None:
            return 0
        try:
            fid = self.session.mech.freedom(driver).id if isinstance(driver, str) else None
        except (InputError, KeyError):
            fid = None
        if fid not in acts:
            raise InputError(f"driver: expected one of the drivers {', '.join(acts)}, got {driver!r}")
        return acts.index(fid)

    def _sample(self, point: np.ndarray) -> dict:
        s = self.session
        m, c = s.mech, s.config
        J = complete_jacobian(m, c)
        ids = [r.id for r in m.freedom_refs]
        joints = freedom_values_dict(m, dict(zip(ids, freedom_values(m, c.q), strict=True)), "joints")
        return {"config": c, "point": (c.D[:3, :3] @ point + c.D[:3, 3]).tolist(), "joints": joints,
                "transmission_min": transmission_readout(J)["transmission_min"], "sigma_min": float(J.sigma_min)}

    def _walk(self, k: int, values: np.ndarray, point: np.ndarray) -> tuple[list, list, str]:
        """Drive driver ``k`` through ``values`` (display units) from the current configuration."""
        s = self.session
        base = _display(s)
        out: list[dict] = []
        inputs: list[float] = []
        stop = ""
        for v in values:
            target = list(base)
            target[k] = float(v)
            try:
                r = s.drive(target, name="sweep")
            except (InputError, ConvergenceError) as e:
                return out, inputs, f"stopped at {v:.6g}: {e}"
            if r.status not in (DriveStatus.REACHED, DriveStatus.UNCHANGED):
                moved = _display(s)[k]
                if (inputs and moved != inputs[-1]) or (not inputs and moved != base[k]):
                    out.append(self._sample(point))  # the last point before the stop
                    inputs.append(moved)
                return out, inputs, f"stopped before {v:.6g}: {r.status}: {r.message}"
            out.append(self._sample(point))
            inputs.append(float(v))
        return out, inputs, stop

    def sweep(self, driver=None, samples: int = SWEEP_SAMPLES, point_len=None) -> dict:
        """Driver ``driver`` (default the first) from its current value to both ends of its slider
        range in ``samples`` values, by continuation (module docstring): ``input`` (degrees or the
        length unit: ``input_unit``), every joint value, ``transmission_min``, ``sigma_min`` and
        the path of ``point_len`` (output-link frame, default the platform point) at each value;
        ``stops`` says where and why either direction stopped."""
        if isinstance(samples, bool) or not isinstance(samples, int) or not 5 <= samples <= 721:
            raise InputError(f"samples: expected a whole number from 5 to 721, got {samples!r}")
        s = self.session
        k = self._driver_index(driver)
        point = s.mech.platform_point if point_len is None else _vec3(point_len, "point_len")
        aid = s.mech.actuators[k]
        lo, hi = s.slider_range(aid, s.start_values[k], s.actuator_values()[k])
        v0 = _display(s)[k]
        kept = self._keep()
        n_up = max(1, round((samples - 1) * (hi - v0) / max(hi - lo, 1e-300)))
        try:
            here = self._sample(point)
            up, x_up, stop_up = self._walk(k, np.linspace(v0, hi, n_up + 1)[1:], point)
            self._put_back(kept)
            down, x_down, stop_down = self._walk(k, np.linspace(v0, lo, samples - n_up)[1:], point)
        finally:
            self._put_back(kept)
        rows = [*reversed(down), here, *up]
        inputs = [*reversed(x_down), v0, *x_up]
        joint_keys = [u for u in ("joints_deg", "joints_len") if rows[0]["joints"].get(u)]
        return {"driver": aid, "input_unit": "deg" if _rotation(s, aid) else s.mech.length_unit, "input": inputs,
                **{u: {j: [r["joints"][u][j] for r in rows] for j in rows[0]["joints"][u]} for u in joint_keys},
                "transmission_min": [r["transmission_min"] for r in rows], "sigma_min": [r["sigma_min"] for r in rows],
                "point_len": [r["point"] for r in rows],
                "stops": [t for t in (stop_down and "decreasing: " + stop_down, stop_up and "increasing: " + stop_up) if t]}

    def coupler_curve(self, point_len=None, frames: int = 240) -> dict:
        """The path of a point fixed to the output link (``point_len``: in the output link's frame,
        the length unit; default the platform point): over the traced circuit of a one-degree-of-
        freedom linkage (``over``: ``"circuit"``), else over the first driver's range (``"sweep"``)."""
        s = self.session
        point = s.mech.platform_point if point_len is None else _vec3(point_len, "point_len")
        if isinstance(frames, bool) or not isinstance(frames, int) or not 10 <= frames <= 2000:
            raise InputError(f"frames: expected a whole number from 10 to 2000, got {frames!r}")
        if len(s.mech.actuators) == 1:
            from ...analysis.traced_motion import traced_motion

            try:
                configs, _ = traced_motion(s.mech, frames=frames, start=s.config)
            except (RuntimeError, ConvergenceError) as e:
                raise ConvergenceError(f"coupler curve: the circuit could not be traced ({e})") from None
            pts = [(c.D[:3, :3] @ point + c.D[:3, 3]).tolist() for c in configs]
            return {"over": "circuit", "point_len": point.tolist(), "curve_len": pts}
        sw = self.sweep(None, min(frames, 721), point.tolist())
        return {"over": "sweep", "driver": sw["driver"], "point_len": point.tolist(), "curve_len": sw["point_len"],
                "stops": sw["stops"]}
