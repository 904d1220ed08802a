"""What changes over time (:class:`State`) and what drives it (:class:`Inputs`, :class:`InputTable`).

A :class:`State` holds only the numbers that move: the time, each free body's and mover's
pose, each URDF robot's joint positions. Everything else (shapes, masses, parsed URDFs,
friction) stays in the :class:`~quasistatic.adapters.World` it is applied to, so a step
re-uses the parsed models and never re-reads a file.
"""

from __future__ import annotations

import bisect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TypeAlias, TypeVar, cast

import numpy as np
import numpy.typing as npt

from ..adapters import AnyWorld, PlanarWorld, Pose, World
from ..errors import SceneError
from ..model import checked_array, checked_number

__all__ = ["State", "Inputs", "InputTable", "InputSource", "inputs_at"]

FloatArray = npt.NDArray[np.float64]
W = TypeVar("W", bound=World | PlanarWorld)  # applied to a World, a state gives a World; to a PlanarWorld, a PlanarWorld


def _frozen(mapping: Mapping[str, object]) -> Mapping[str, object]:
    return MappingProxyType(dict(mapping))


@dataclass(frozen=True)
class State:
    """The configuration at one instant: time, free-body and mover poses, robot joint positions."""

    time: float
    bodies: Mapping[str, Pose]
    movers: Mapping[str, Pose]
    robots: Mapping[str, FloatArray]

    @classmethod
    def of(cls, world: AnyWorld, time: float = 0.0) -> State:
        """The state a World describes."""
        return cls(
            time,
            _frozen({b.name: b.pose for b in world.bodies}),  # type: ignore[arg-type]
            _frozen({m.name: m.pose for m in world.movers}),  # type: ignore[arg-type]
            _frozen({r.name: np.array(r.q, dtype=float) for r in world.robots}),  # type: ignore[arg-type]
        )

    def applied(self, world: W) -> W:
        """``world`` at this state: the same shapes and parsed models (and detection layout), placed here."""
        return cast(W, world.moved(self.bodies, self.robots, mover_poses=self.movers))


@dataclass(frozen=True)
class Inputs:
    """What the user commands at one instant: joint velocities per robot, twists per mover.

    A mover's twist is [velocity of its pose origin, angular velocity] in the world frame, as in
    a scene file: 6 entries in space, 3 ([vx, vy, w]) in a planar world. Robots and movers not named keep the velocities of the scene.
    """

    joint_velocities: Mapping[str, FloatArray]
    mover_twists: Mapping[str, FloatArray]

    def __init__(
        self, joint_velocities: Mapping[str, npt.ArrayLike] | None = None, mover_twists: Mapping[str, npt.ArrayLike] | None = None
    ) -> None:
        velocities = {n: checked_array(v, f"inputs.joint_velocities.{n}") for n, v in (joint_velocities or {}).items()}
        twists = {n: checked_array(t, f"inputs.mover_twists.{n}") for n, t in (mover_twists or {}).items()}
        for name, twist in twists.items():
            if twist.shape not in ((6,), (3,)):
                reason = "a twist has 6 entries, [vx, vy, vz, wx, wy, wz] (3 in a planar world: [vx, vy, w])"
                raise SceneError(f"inputs.mover_twists.{name}", twist.tolist(), reason)
        object.__setattr__(self, "joint_velocities", _frozen(velocities))
        object.__setattr__(self, "mover_twists", _frozen(twists))

    @classmethod
    def of(cls, world: AnyWorld) -> Inputs:
        """The velocities a World's scene describes."""
        size = 3 if world.dimension == 2 else 6
        twists = {m.name: np.zeros(size) if m.twist is None else np.asarray(m.twist, dtype=float) for m in world.movers}
        return cls({r.name: r.joint_velocities for r in world.robots}, twists)

    def check(self, world: AnyWorld) -> None:
        """Every name is a robot or mover of ``world``, with the right number of joint velocities and twist entries."""
        robots = {r.name: r for r in world.robots}
        movers = {m.name for m in world.movers}
        for name, velocities in self.joint_velocities.items():
            if name not in robots:
                raise SceneError("inputs.joint_velocities", name, f"names no URDF robot of the scene (robots: {sorted(robots)})")
            count = len(robots[name].joint_names)
            if velocities.shape != (count,):
                raise SceneError(f"inputs.joint_velocities.{name}", velocities.tolist(), f"needs {count} values, one per joint")
        size = 3 if world.dimension == 2 else 6
        for name, twist in self.mover_twists.items():
            if name not in movers:
                raise SceneError("inputs.mover_twists", name, f"names no mover of the scene (movers: {sorted(movers)})")
            if twist.shape != (size,):
                reason = f"a twist in this {world.dimension}-D world has {size} entries"
                raise SceneError(f"inputs.mover_twists.{name}", twist.tolist(), reason)

    def applied(self, world: W) -> W:
        """``world`` with these velocities; what is not named keeps the scene's."""
        return cast(W, world.moved(joint_velocities=self.joint_velocities, mover_twists=self.mover_twists))


@dataclass(frozen=True)
class InputTable:
    """Inputs over time, held from each listed time until the next (the last held to the end).

    ``times`` must start at 0 and increase strictly.
    """

    times: tuple[float, ...]
    inputs: tuple[Inputs, ...]

    def __post_init__(self) -> None:
        times = tuple(checked_number(t, f"inputs.times[{i}]", minimum=0.0) for i, t in enumerate(self.times))
        if not times or times[0] != 0.0 or any(b <= a for a, b in zip(times, times[1:], strict=False)):
            raise SceneError("inputs.times", list(self.times), "must start at 0 and increase strictly")
        if len(self.inputs) != len(times):
            raise SceneError("inputs.inputs", len(self.inputs), f"needs one Inputs per time ({len(times)})")
        object.__setattr__(self, "times", times)

    def at(self, time: float) -> Inputs:
        return self.inputs[bisect.bisect_right(self.times, time) - 1]

    def changes_after(self, time: float) -> float | None:
        """The first time after ``time`` at which the inputs change (a step must not cross it)."""
        index = bisect.bisect_right(self.times, time)
        return self.times[index] if index < len(self.times) else None


InputSource: TypeAlias = Inputs | InputTable | Callable[[float, State], Inputs] | None
"""Constant inputs, a table over time, a function of the time and state, or None: the scene's own velocities."""


def inputs_at(source: InputSource, state: State) -> Inputs:
    """The inputs in force at ``state``."""
    if source is None:
        return Inputs()
    if isinstance(source, Inputs):
        return source
    if isinstance(source, InputTable):
        return source.at(state.time)
    result = source(state.time, state)
    if not isinstance(result, Inputs):
        raise TypeError(f"an inputs function must return quasistatic.sim.Inputs, not {type(result).__name__}")
    return result
