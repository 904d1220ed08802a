"""A run's result: the states, what happened at each, the events; saved as ``.npz`` or JSON Lines and read back."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np
import numpy.typing as npt

from ..adapters import AnyWorld, PlanarWorld, Pose, World
from ..errors import QuasistaticError, SceneError
from ..loading import load_world
from ..solution import Status
from .state import State
from .step import ContactRecord, Event, StepResult

__all__ = ["RunStatus", "Trajectory"]

FloatArray = npt.NDArray[np.float64]
RunStatus = Literal["completed", "jammed", "unstable", "ambiguous", "failed", "max_steps"]
FORMAT = "quasistatic-trajectory"
VERSION = 1


@dataclass(frozen=True)
class Trajectory:
    """States at increasing times, and for each the answer there and the step taken from it.

    ``steps[i]`` belongs to ``states[i]``; the last step has ``dt`` 0. ``status`` says how the run
    ended: ``completed`` (the whole duration), or the status that stopped it, with ``message``.
    ``scene_file``: the absolute path of the scene file it was run on ("" for a World built in Python),
    so that ``quasistatic animate`` can draw it.
    """

    states: tuple[State, ...]
    steps: tuple[StepResult, ...]
    status: RunStatus
    message: str
    scene_file: str = ""

    @property
    def times(self) -> FloatArray:
        return np.array([s.time for s in self.states])

    @property
    def certified(self) -> bool:
        """Every step's answer was certified (proven unique, or its list complete)."""
        return all(s.certified for s in self.steps)

    @property
    def events(self) -> tuple[Event, ...]:
        return tuple(e for s in self.steps for e in s.events)

    @property
    def max_penetration(self) -> float:
        """The deepest penetration found at any step, before it was corrected [length]."""
        return max((s.penetration for s in self.steps), default=0.0)

    @property
    def final(self) -> State:
        return self.states[-1]

    def positions(self, body: str) -> FloatArray:
        """The body's (or mover's) pose origin at every state, (n, 3)."""
        return np.array([_pose(s, body).position for s in self.states])

    def rotations(self, body: str) -> FloatArray:
        """The body's (or mover's) rotation matrix at every state, (n, 3, 3)."""
        return np.array([_pose(s, body).rotation for s in self.states])

    def scene_world(self) -> AnyWorld:
        """The World of :attr:`scene_file`, read again (to draw the run on: the states place it).

        Raises :class:`SceneError` when the trajectory names no scene file (it was run on a World built in
        Python), or the file lists its contacts instead of shapes.
        """
        if not self.scene_file:
            raise SceneError("scene", "", "the trajectory names no scene file (it was run on a World built in Python): give the World")
        world = load_world(self.scene_file)
        if not isinstance(world, World | PlanarWorld):
            raise SceneError("scene", self.scene_file, "lists its contacts: a trajectory is run on a scene of shapes")
        return world

    def _repr_html_(self) -> str:
        """Jupyter's view of the run: how it ended, whether every step is proven, its events, and a small GIF of it
        on the scene file it names (when that file is there and matplotlib is installed)."""
        from ..viz.run_summary import trajectory_html  # the one way from a run to the pictures (it imports no Trajectory)

        try:
            world, why = self.scene_world(), ""
        except (QuasistaticError, OSError) as error:
            world, why = None, str(error)
        return trajectory_html(self, world, why)

    def joint_positions(self, robot: str) -> FloatArray:
        """A URDF robot's joint positions at every state, (n, joints)."""
        return np.array([s.robots[robot] for s in self.states])

    # ----------------------------------------------------------------- files

    def save(self, path: str | Path) -> Path:
        """Write ``.npz`` (arrays of poses and joints, the steps as JSON) or ``.jsonl`` (one line per state)."""
        path = Path(path)
        if path.suffix == ".npz":
            np.savez_compressed(path, **self._arrays())
        elif path.suffix == ".jsonl":
            lines = [json.dumps(self._header())] + [
                json.dumps(_state_dict(s) | {"step": _step_dict(r)}) for s, r in zip(self.states, self.steps, strict=True)
            ]
            path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        else:
            raise SceneError("out", Path(path), "a trajectory is saved as .npz or .jsonl")
        return path

    @classmethod
    def load(cls, path: str | Path) -> Trajectory:
        """A trajectory written by :meth:`save`."""
        path = Path(path)
        try:
            if path.suffix == ".npz":
                return cls._from_arrays(path)
            if path.suffix == ".jsonl":
                return cls._from_lines(path)
        except (OSError, ValueError, KeyError, TypeError, IndexError) as error:
            raise SceneError(
                "trajectory", str(path), f"is not a trajectory written by quasistatic ({type(error).__name__}: {error})"
            ) from None
        raise SceneError("trajectory", Path(path), "a trajectory file ends in .npz or .jsonl")

    def _header(self) -> dict[str, Any]:
        return {
            "format": FORMAT, "version": VERSION, "status": self.status, "message": self.message,
            "certified": self.certified, "scene_file": self.scene_file,
        }  # fmt: skip

    def _arrays(self) -> dict[str, Any]:
        first = self.states[0]
        arrays: dict[str, Any] = {"times": self.times}
        names = {"bodies": list(first.bodies), "movers": list(first.movers), "robots": list(first.robots)}
        for kind in ("bodies", "movers"):
            for i, name in enumerate(names[kind]):
                arrays[f"{kind}{i}_position"] = self.positions(name)
                arrays[f"{kind}{i}_rotation"] = self.rotations(name)
        for i, name in enumerate(names["robots"]):
            arrays[f"robots{i}_q"] = self.joint_positions(name)
        document = self._header() | {"names": names, "steps": [_step_dict(r) for r in self.steps]}
        arrays["document"] = np.array(json.dumps(document))
        return arrays

    @classmethod
    def _from_arrays(cls, path: Path) -> Trajectory:
        with np.load(path, allow_pickle=False) as data:
            document = _checked_header(json.loads(str(data["document"])))
            names = document["names"]
            times = data["times"]
            poses = {
                kind: {name: (data[f"{kind}{i}_position"], data[f"{kind}{i}_rotation"]) for i, name in enumerate(names[kind])}
                for kind in ("bodies", "movers")
            }
            joints = {name: data[f"robots{i}_q"] for i, name in enumerate(names["robots"])}
            states = tuple(
                State(
                    float(t),
                    {n: _trusted(p[k], r[k]) for n, (p, r) in poses["bodies"].items()},
                    {n: _trusted(p[k], r[k]) for n, (p, r) in poses["movers"].items()},
                    {n: np.array(q[k], dtype=float) for n, q in joints.items()},
                )
                for k, t in enumerate(times)
            )
        steps = tuple(_step_from(s) for s in document["steps"])
        return cls(states, steps, document["status"], document["message"], str(document.get("scene_file", "")))

    @classmethod
    def _from_lines(cls, path: Path) -> Trajectory:
        lines = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
        header = _checked_header(lines[0])
        states = tuple(_state_from(line) for line in lines[1:])
        steps = tuple(_step_from(line["step"]) for line in lines[1:])
        return cls(states, steps, header["status"], header["message"], str(header.get("scene_file", "")))


def _pose(state: State, name: str) -> Pose:
    if name in state.bodies:
        return state.bodies[name]
    if name in state.movers:
        return state.movers[name]
    raise SceneError(
        "body", name, f"names no body or mover of the trajectory (bodies: {sorted(state.bodies)}, movers: {sorted(state.movers)})"
    )


def _checked_header(header: dict[str, Any]) -> dict[str, Any]:
    if header.get("format") != FORMAT or header.get("version") != VERSION:
        raise ValueError(f"expected format {FORMAT!r} version {VERSION}")
    return header


def _trusted(position: Any, rotation: Any) -> Pose:
    return Pose.from_trusted_arrays(np.array(position, dtype=float), np.array(rotation, dtype=float))


def _floats(values: Any) -> list[Any]:
    return cast(list[Any], np.asarray(values, dtype=float).tolist())


def _state_dict(state: State) -> dict[str, Any]:
    def poses(mapping: Any) -> dict[str, Any]:
        return {n: {"position": _floats(p.position), "rotation": _floats(p.rotation)} for n, p in mapping.items()}

    return {
        "time": state.time,
        "bodies": poses(state.bodies),
        "movers": poses(state.movers),
        "robots": {n: _floats(q) for n, q in state.robots.items()},
    }


def _state_from(line: dict[str, Any]) -> State:
    def poses(mapping: dict[str, Any]) -> dict[str, Pose]:
        return {n: _trusted(p["position"], p["rotation"]) for n, p in mapping.items()}

    return State(
        float(line["time"]), poses(line["bodies"]), poses(line["movers"]), {n: np.array(q, dtype=float) for n, q in line["robots"].items()}
    )


def _step_dict(step: StepResult) -> dict[str, Any]:
    return {
        "time": step.time,
        "dt": step.dt,
        "status": step.status,
        "certified": step.certified,
        "message": step.message,
        "twists": {n: _floats(t) for n, t in step.twists.items()},
        "contacts": [
            {
                "body": c.body,
                "other": c.other,
                "point": _floats(c.point),
                "normal": _floats(c.normal),
                "gap": c.gap,
                "force": _floats(c.force),
                "mode": c.mode,
                "slip": _floats(c.slip),
            }
            for c in step.contacts
        ],
        "choice": step.choice,
        "penetration": step.penetration,
        "events": [
            {"time": e.time, "kind": e.kind, "pair": list(e.pair), "detail": e.detail, "window": list(e.window)} for e in step.events
        ],
    }


def _step_from(data: dict[str, Any]) -> StepResult:
    contacts = tuple(
        ContactRecord(
            c["body"],
            c["other"],
            np.array(c["point"]),
            np.array(c["normal"]),
            float(c["gap"]),
            np.array(c["force"]),
            c["mode"],
            np.array(c.get("slip", (0.0, 0.0, 0.0)), dtype=float),  # files written before slips were kept
        )  # fmt: skip
        for c in data["contacts"]
    )
    events = tuple(
        Event(
            float(e["time"]),
            e["kind"],
            (e["pair"][0], e["pair"][1]) if e["pair"] else ("", ""),
            e["detail"],
            (e["window"][0], e["window"][1]),
        )
        for e in data["events"]
    )
    status: Status = data["status"]
    return StepResult(
        float(data["time"]),
        float(data["dt"]),
        status,
        bool(data["certified"]),
        data["message"],
        {n: np.array(t, dtype=float) for n, t in data["twists"].items()},
        contacts,
        data["choice"],
        float(data["penetration"]),
        events,
    )
