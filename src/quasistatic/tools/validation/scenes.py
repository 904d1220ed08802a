"""Scene mutation: a case's scene dict with its overrides, the 3-D extrusion, and the parameters a bisection varies."""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .cases import Case, read_yaml


def scene_data(case: Case) -> dict[str, Any]:
    """The scene dict of a case: its file, with the case's overrides, extruded for a 3-D run.

    Parameters
    ----------
    case : Case

    Returns
    -------
    dict
        A fresh copy, safe to change.
    """
    data = copy.deepcopy(read_yaml(case.folder / case.scene))
    for path, value in case.overrides.items():
        _set_path(data, path, copy.deepcopy(value))
    return extrude(data, case.depth) if case.depth is not None else data


def _set_path(data: Any, path: str, value: Any) -> None:
    """Replace ``data[...]`` at a dotted path with ``[index]`` parts, e.g. ``contacts[2].point``."""
    keys: list[str | int] = [int(k[1:-1]) if k.startswith("[") else k for k in re.findall(r"\[\d+\]|[^.\[\]]+", path)]
    target = data
    for key in keys[:-1]:
        target = target[key]
    target[keys[-1]] = value


def extrude(data: Mapping[str, Any], depth: float) -> dict[str, Any]:
    """A planar scene dict extruded along z: every contact duplicated at z = -depth/2 and +depth/2.

    Vectors gain a zero z entry, planar twists ``[vx, vy, wz]`` and wrenches
    ``[fx, fy, mz]`` become ``[vx, vy, 0, 0, 0, wz]`` and ``[fx, fy, 0, 0, 0, mz]``.
    Contact ``i`` of the planar scene becomes contacts ``2i`` (z = -depth/2) and ``2i + 1``.

    Parameters
    ----------
    data : mapping
        A planar scene dict (``dimension: 2``); left unchanged.
    depth : float
        Distance between the two copies of each contact [m].

    Raises
    ------
    ValueError
        When the scene is not planar.
    """
    if data.get("dimension", 3) != 2:
        raise ValueError("only a planar scene (dimension: 2) can be extruded")
    out = {k: copy.deepcopy(v) for k, v in data.items() if k not in ("dimension", "gravity", "bodies", "movers", "contacts")}
    out["dimension"] = 3
    out["gravity"] = [*data.get("gravity", [0.0, -9.81]), 0.0]
    out["bodies"] = {name: _extrude_body(body) for name, body in data["bodies"].items()}
    out["movers"] = {name: _extrude_mover(mover) for name, mover in (data.get("movers") or {}).items()}
    out["contacts"] = [
        {**contact, "point": [*contact["point"], z], "normal": [*contact["normal"], 0.0]}
        for contact in data["contacts"]
        for z in (-depth / 2, depth / 2)
    ]
    return out


def _extrude_body(body: Mapping[str, Any]) -> dict[str, Any]:
    """A body of a planar scene in 3-D: com on z = 0, a planar wrench made spatial."""
    out = dict(body)
    out["com"] = [*body["com"], 0.0]
    if body.get("wrench") is not None:
        out["wrench"] = to_spatial(body["wrench"])
    return out


def _extrude_mover(mover: Mapping[str, Any] | None) -> dict[str, Any]:
    """A mover of a planar scene in 3-D: a planar twist made spatial, origin on z = 0."""
    out = dict(mover or {})
    if out.get("twist") is not None:
        out["twist"] = to_spatial(out["twist"])
    if out.get("origin") is not None:
        out["origin"] = [*out["origin"], 0.0]
    return out


def to_spatial(planar: Sequence[float]) -> list[float]:
    """A planar twist ``[vx, vy, wz]`` (or wrench ``[fx, fy, mz]``) as ``[vx, vy, 0, 0, 0, wz]``."""
    vx, vy, wz = planar
    return [vx, vy, 0.0, 0.0, 0.0, wz]


def slope_deg(data: dict[str, Any], angle: float, params: Mapping[str, Any]) -> None:
    """Tilt gravity so that the x axis is a slope rising at ``angle`` degrees."""
    g = float(np.linalg.norm(data.get("gravity", [0.0, -9.81])))
    a = math.radians(angle)
    data["gravity"] = [-g * math.sin(a), -g * math.cos(a)]


def ladder_deg(data: dict[str, Any], angle: float, params: Mapping[str, Any]) -> None:
    """Stand the ladder at ``angle`` degrees: contact 0 its foot on the floor y = 0, contact 1 its top on the wall x = 0.

    Raises
    ------
    ValueError
        When contacts 0 and 1 are not on the floor and the wall.
    """
    foot, top = data["contacts"][0], data["contacts"][1]
    if list(foot["normal"]) != [0.0, 1.0] or list(top["normal"]) != [1.0, 0.0]:
        raise ValueError("ladder_deg needs contact 0 on the floor (normal [0, 1]) and contact 1 on the wall (normal [1, 0])")
    length = math.dist(foot["point"], top["point"])
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    foot["point"] = [length * c, 0.0]
    top["point"] = [0.0, length * s]
    data["bodies"][foot["body"]]["com"] = [length * c / 2, length * s / 2]


def push_height(data: dict[str, Any], height: float, params: Mapping[str, Any]) -> None:
    """Move the last contact (the pusher's) to height ``height``."""
    data["contacts"][-1]["point"] = [data["contacts"][-1]["point"][0], height]
