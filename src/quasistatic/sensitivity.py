"""``sensitivity(scene)``: the exact derivative of a solved motion with respect to the commanded inputs.

The inputs are the robots' joint velocities and the rigid movers' twists
(:class:`~quasistatic.laws.inputs.InputVector`); the work is done by
:func:`quasistatic.derivative.differentiate`, which ``solution.sensitivity()``
also reaches. This function only solves the scene first when no answer is given.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

from .adapters import UrdfRobot
from .derivative import GeometrySensitivity, InputMargin, ModeChange, NoSensitivity, NoSensitivityReason, Sensitivity, differentiate
from .model import Scene
from .solution import Solution
from .solve import solve

__all__ = ["sensitivity", "Sensitivity", "GeometrySensitivity", "NoSensitivity", "NoSensitivityReason", "ModeChange", "InputMargin"]


def sensitivity(
    scene: Scene,
    solution: Solution | None = None,
    *,
    inputs: Collection[str] | None = None,
    geometry: bool = False,
    robots: Sequence[UrdfRobot] = (),
) -> Sensitivity | NoSensitivity:
    """The derivative of the scene's solved motion with respect to its inputs.

    Parameters
    ----------
    scene : Scene
    solution : Solution, optional
        The scene's answer (``solve(scene)`` when omitted). Only a ``solved`` motion has a derivative.
    inputs : collection of str, optional
        Names of the robots and rigid movers whose inputs to differentiate by (all of them when omitted).
    geometry : bool
        Also differentiate with respect to each contact's point and normal (``Sensitivity.geometry``).
    robots : sequence of UrdfRobot
        With ``geometry``: also with respect to these URDF robots' joint positions, contact points and normals
        held (a Solution of a World passes its robots itself: ``solution.sensitivity(geometry=True)``).

    Returns
    -------
    Sensitivity, or NoSensitivity with the reason there is none.
    """
    return differentiate(scene, solve(scene) if solution is None else solution, inputs=inputs, geometry=geometry, robots=robots)
