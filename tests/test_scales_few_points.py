"""A small scene's scales are worked out in Python floats (``model/scales.py``, below ``ORDERED_SUMS`` points), term
for term in NumPy's order: they must equal the array computation to the last bit, or every tolerance and every
scene-relative number of a step would move."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import quasistatic as qs
from quasistatic.model import scales
from quasistatic.model.kinematics import mover_point_velocities

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _random_scene(rng: np.random.Generator, dimension: int, contacts: int) -> qs.Scene:
    size = rng.uniform(1e-3, 1e3)
    normals = rng.normal(size=(contacts, dimension))
    return qs.Scene(
        bodies=[qs.Body("box", rng.uniform(0.1, 10.0), com=rng.normal(size=dimension) * size)],
        movers=[qs.Mover("hand", twist=rng.normal(size=3 if dimension == 2 else 6))],
        contacts=[
            qs.Contact("box", "hand", point=rng.normal(size=dimension) * size, normal=n / np.linalg.norm(n), mu=0.5) for n in normals
        ],
        dimension=dimension,
    )


def _scenes() -> list[qs.Scene]:
    rng = np.random.default_rng(7)
    found = [_random_scene(rng, dimension, contacts) for dimension in (2, 3) for contacts in range(1, 7) for _ in range(5)]
    world = qs.load_world(EXAMPLES / "sim" / "tip_box_planar.yaml")
    return [*found, world.scene(world.detect())]


@pytest.mark.parametrize("scene", _scenes())
def test_few_point_scales_equal_the_array_computation_to_the_last_bit(scene: qs.Scene, monkeypatch: pytest.MonkeyPatch) -> None:
    assert len(scene.contacts) + len(scene.bodies) < scales.ORDERED_SUMS  # the Python-float path
    velocities = mover_point_velocities(scene)
    few = scales.scene_scales(scene, velocities)
    monkeypatch.setattr(scales, "ORDERED_SUMS", 0)  # every scene through the arrays
    arrays = scales.scene_scales(scene, velocities)
    assert (few.length, few.force, few.velocity) == (arrays.length, arrays.force, arrays.velocity)
    assert few.origin.tobytes() == arrays.origin.tobytes() and not few.origin.flags.writeable
