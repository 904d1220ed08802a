"""The files an animation is written as, checked before anything is drawn or imported.

Kept apart from :mod:`.animation` (which imports ``sim/`` and, through it, the solvers) so that the CLI
refuses a bad ``--output`` at once.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from ..errors import SceneError

__all__ = ["ANIMATION_FORMATS", "animation_output"]

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
