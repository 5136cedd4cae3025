"""Frames to files: a looping GIF (Pillow), or H.264 video through the optional package imageio-ffmpeg."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image


def ffmpeg():
    """The optional module imageio_ffmpeg, or an error saying how to get it."""
    try:
        import imageio_ffmpeg
    except ImportError as err:
        raise ModuleNotFoundError("MP4 animations need the optional package imageio-ffmpeg "
                                  "(pip install imageio-ffmpeg); write a .gif instead") from err
    return imageio_ffmpeg


def write_gif(frames, path: Path, fps: float) -> None:
    first, *rest = (Image.fromarray(f) for f in frames)
    first.save(path, save_all=True, append_images=rest, duration=round(1000 / fps), loop=0)


def write_mp4(ffmpeg, frames, path: Path, fps: float) -> None:
    """H.264 in yuv420p through imageio-ffmpeg; frames are padded to even width and height."""
    writer = None
    for image in frames:
        h, w = image.shape[:2]
        image = np.pad(image, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        if writer is None:
            writer = ffmpeg.write_frames(str(path), (image.shape[1], image.shape[0]), fps=fps,
                                         macro_block_size=1, pix_fmt_out="yuv420p")
            writer.send(None)
        writer.send(np.ascontiguousarray(image))
    writer.close()
