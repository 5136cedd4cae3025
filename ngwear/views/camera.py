"""How a picture is framed: the camera looks at its subject and fills :data:`FRAME` with it (parallel projection)."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from .picture_data import PictureData

FRAME = (0.03, 0.79, 0.08, 0.9)
"""Where a picture's subject goes: the window's fraction from its left (0) to right (1) and bottom to top, leaving
the scalar bars on the right, the caption above and the note below."""


def aim(pl: pv.Plotter, picture: PictureData, window_size) -> None:
    """Look at the picture's subject and fill :data:`FRAME` with it (parallel projection).

    A 3D part is seen from below, through the translucent foundation, onto its worn contact face (from further
    below on a rotor, so that the whole face shows); it is framed with its layer and the arrow of the foundation's
    motion (:meth:`PictureData.framed`).  A 2D picture is seen from the front, the foundation's block included.
    """
    pl.enable_parallel_projection()
    if picture.dim == 3:
        pl.view_xz()
        pl.camera.azimuth, pl.camera.elevation = -25, -55 if picture.rotor is not None else -40
        points = picture.framed()
        level(pl.camera, points)
    else:
        pl.camera.position, pl.camera.focal_point, pl.camera.up = (0, 0, 10), (0, 0, 0), (0, 1, 0)
        x0, x1, y0, y1 = picture.view()
        points = np.array([[x0, y0, 0.0], [x1, y1, 0.0]])
    fit(pl.camera, points, window_size[0] / window_size[1])
    pl.reset_camera_clipping_range()


def level(camera, points: np.ndarray) -> None:
    """Turn the camera about its direction so that the longest extent of ``points`` runs across the window."""
    forward = np.asarray(camera.direction)
    up = np.asarray(camera.up) - (np.asarray(camera.up) @ forward) * forward
    up /= np.linalg.norm(up)
    right = np.cross(forward, up)
    seen = np.column_stack([points @ right, points @ up])
    major = np.linalg.eigh(np.cov(seen.T))[1][:, -1]          # the principal axis of the points as seen
    angle = np.arctan2(major[1], major[0])
    angle = (angle + np.pi / 2) % np.pi - np.pi / 2            # the smaller turn: within ±90°
    camera.up = np.cos(angle) * up - np.sin(angle) * right


def fit(camera, points: np.ndarray, aspect: float) -> None:
    """Point the camera (its direction and up kept) at the middle of ``points`` so that they fill :data:`FRAME`."""
    forward = np.asarray(camera.direction)
    up = np.asarray(camera.up) - (np.asarray(camera.up) @ forward) * forward
    up /= np.linalg.norm(up)
    right = np.cross(forward, up)
    across, along, deep = points @ right, points @ up, points @ forward
    left, width, bottom, height = FRAME[0], FRAME[1] - FRAME[0], FRAME[2], FRAME[3] - FRAME[2]
    scale = max(np.ptp(along) / height, np.ptp(across) / (width * aspect), 1e-300) / 2   # half the window's height
    middle = np.array([across.min() + np.ptp(across) / 2, along.min() + np.ptp(along) / 2])
    shift = 2 * scale * np.array([aspect * (0.5 - left - width / 2), 0.5 - bottom - height / 2])
    focus = (middle[0] + shift[0]) * right + (middle[1] + shift[1]) * up + deep.mean() * forward
    camera.focal_point, camera.position = focus, focus - (np.ptp(deep) + 4 * scale) * forward
    camera.parallel_scale = scale
