"""OpenCV (module ``cv2``), or an ImportError that names it and says how to install it."""

from __future__ import annotations

try:
    import cv2
except ModuleNotFoundError as exc:
    raise ModuleNotFoundError(
        "No module named 'cv2': pegame-vision needs OpenCV, pip install 'opencv-contrib-python-headless>=4.8'",
        name="cv2",
    ) from exc

__all__ = ["cv2"]
