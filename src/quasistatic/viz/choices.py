"""The choices a picture offers: the views of a 3-D scene and the files an animation is written as.

Kept apart from :mod:`.geometry` (which imports ``adapters/``, numba with it) and :mod:`.animation` (``sim/``
and, through it, the solvers) so that the CLI refuses a bad ``--view`` or ``--output`` at once.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..errors import SceneError

__all__ = ["ANIMATION_FORMATS", "VIEWS", "animation_output"]

FloatArray = npt.NDArray[np.float64]

_ISO_RIGHT = np.array([1.0, 1.0, 0.0]) / math.sqrt(2.0)
_ISO_UP = np.array([-1.0, 1.0, 2.0]) / math.sqrt(6.0)
# Page axes (right, up) of each view, world coordinates; "iso" looks from (1, -1, 1) with z up.
VIEWS: dict[str, tuple[FloatArray, FloatArray]] = {
    "iso": (_ISO_RIGHT, _ISO_UP),
    "xy": (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])),
    "xz": (np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])),
    "yz": (np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])),
}
ANIMATION_FORMATS = (".gif", ".mp4")


def animation_output(output: str | Path) -> Path:
    """``output`` as a Path, if an animation can be written there: ``.gif``, or ``.mp4`` with ffmpeg on the PATH.

    Raises :class:`SceneError` (field ``output``) otherwise."""
    output = Path(output)
    suffix = output.suffix.lower()
    if suffix not in ANIMATION_FORMATS:
        raise SceneError("output", str(output), f"an animation is written as {' or '.join(ANIMATION_FORMATS)}")
    if suffix == ".mp4" and shutil.which("ffmpeg") is None:
        raise SceneError("output", str(output), "an .mp4 needs ffmpeg on the PATH (apt-get install ffmpeg); write a .gif instead")
    return output
