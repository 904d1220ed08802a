"""The viser server both viewers run on: started quietly, lit evenly, the camera placed on the scene.

Shared by :mod:`.viewer` (one answer, live re-solves) and :mod:`.timeline` (a trajectory), so
that both look alike and fail alike: a bad host or port is one error naming the field.
"""

from __future__ import annotations

import io
import socket
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager, redirect_stdout
from typing import Any

import numpy as np

from ..errors import BackendUnavailableError
from .geometry import VIEWS, FloatArray

__all__ = [
    "VIEWER_INSTALL_HINT",
    "place_camera",
    "quiet",
    "require_viser",
    "serve_until_interrupted",
    "start_server",
    "stop_server",
    "url_of",
]

VIEWER_INSTALL_HINT = 'install viser with pip install "quasistatic[viewer]"'
_AMBIENT = 1.0  # ambient light: alone, it shows every colour flat
_KEY = 0.5  # a directional light from above the camera: it shades the faces of a shape apart
_CAMERA_DISTANCE = 1.2  # the camera starts this many scene sizes from the scene's centre


def require_viser() -> None:
    """Raise :class:`BackendUnavailableError` with the install line when viser is missing."""
    try:
        import viser  # noqa: F401
    except ImportError as exc:
        raise BackendUnavailableError("viser", VIEWER_INSTALL_HINT, needed_for="the viewer") from exc


def start_server(host: str, port: int, verbose: bool) -> Any:
    """A viser server listening on ``host:port`` (the next free port when taken; 0: any free one), evenly lit."""
    require_viser()
    import viser

    _check_listen(host, port)
    with quiet(not verbose):  # viser prints a banner whatever its own verbose says
        server = viser.ViserServer(host=host, port=port, verbose=verbose)
    server.gui.configure_theme(control_width="large")
    _light(server.scene)
    return server


def stop_server(server: Any) -> None:
    with quiet(True):  # viser says "Server stopped" on stdout
        server.stop()


def serve_until_interrupted(stop: Callable[[], None]) -> None:
    """Block until Ctrl-C (the server runs in its own threads), then ``stop``."""
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        stop()


def url_of(server: Any) -> str:
    """The address to open in a browser."""
    host = server.get_host()
    return f"http://{'localhost' if host in ('0.0.0.0', '::') else host}:{server.get_port()}"


def place_camera(server: Any, centre: FloatArray, size: float, dimension: int, view: str = "iso") -> None:
    """A 2-D scene seen from above (y up); a 3-D one as the pictures' ``view`` shows it (one of :data:`VIEWS`:
    ``iso`` looks from (1, -1, 1) with z up, ``xz`` from -y, ...)."""
    if view not in VIEWS:
        raise ValueError(f"view: {view!r} is not one of {', '.join(VIEWS)}")
    camera = server.initial_camera
    if dimension == 2:
        camera.position = tuple(centre + [0.0, 0.0, 2 * _CAMERA_DISTANCE * size])
        camera.up = (0.0, 1.0, 0.0)
    else:
        right, up = VIEWS[view]
        towards = np.cross(right, up)
        camera.position = tuple(centre + _CAMERA_DISTANCE * size * np.sqrt(3.0) * towards / np.linalg.norm(towards))
        camera.up = tuple(up)
    camera.look_at = tuple(centre)


@contextmanager
def quiet(enabled: bool) -> Iterator[None]:
    """What viser prints to stdout, dropped (the command prints its own line with the address)."""
    if not enabled:
        yield
        return
    with redirect_stdout(io.StringIO()):
        yield


def _light(api: Any) -> None:
    """Even light, no environment reflections: a part's colour on screen stays near its colour in the pictures."""
    api.configure_environment_map(hdri=None)
    api.configure_default_lights(enabled=False)
    api.add_light_ambient("/lights/ambient", intensity=_AMBIENT)
    api.add_light_directional("/lights/key", intensity=_KEY, position=(1.0, -1.0, 2.0))


def _check_listen(host: str, port: int) -> None:
    """Fail early, with the field named, where the server could not listen (viser would retry other ports forever)."""
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ValueError(f"port: {port!r} is not a port number (0 to 65535; 0 picks a free one)")
    try:
        family, kind, _, _, address = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)[0]
        with socket.socket(family, kind) as probe:
            probe.bind((address[0], 0))
    except (OSError, UnicodeError) as exc:
        raise ValueError(f"host: cannot listen on {host!r}: {exc}") from exc
