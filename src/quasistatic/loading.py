"""Scene files in, Scenes out: listed contacts are read as they are; shapes and URDF robots have theirs found.

``quasistatic.load_scene`` reads either kind of file. A file that lists every
contact becomes a :class:`Scene` in :mod:`quasistatic.model.io`; one with
shapes, poses or URDF robots becomes a :class:`~quasistatic.adapters.World`,
whose contacts are found (coal) and whose robot Jacobians are computed
(Pinocchio) at the configuration the file gives.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .model import Scene
from .model.io import read_scene_file, scene_from_file

if TYPE_CHECKING:
    from .adapters import AnyWorld

__all__ = ["load_scene", "load_world"]


def load_scene(source: str | Path | Mapping[str, Any]) -> Scene:
    """The Scene of a YAML/JSON file or a dict of its keys, with its contacts found if it describes shapes.

    Raises
    ------
    SceneError
        Naming the field and the value (a missing URDF or mesh included).
    BackendUnavailableError
        For 3-D shapes or URDF robots without the ``robots`` extra installed (planar shapes need none).
    """
    loaded = load_world(source)
    return loaded if isinstance(loaded, Scene) else loaded.scene()


def load_world(source: str | Path | Mapping[str, Any]) -> Scene | AnyWorld:
    """A file that lists its contacts as a Scene; one with shapes or URDF robots as a World, a planar one
    (``dimension: 2``) as a PlanarWorld (contacts not yet found)."""
    parsed, folder = read_scene_file(source)
    if not parsed.is_geometric:
        return scene_from_file(parsed)
    from .adapters import world_from_file  # detection and its kernels load only for scenes of shapes

    return world_from_file(parsed, folder)
