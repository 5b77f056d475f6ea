from numpy.typing import ArrayLike

def e_dist(gt: ArrayLike, pred: ArrayLike) -> float:
    """Mean vertex distance between ``gt`` and ``pred`` (float [N,3] each, metres), in cm."""

def e_norm(gt: ArrayLike, pred: ArrayLike, faces: ArrayLike) -> float:
    """Mean face-normal angle between ``gt`` and ``pred`` (float [N,3]) over ``faces``
    (int [F,3]), in degrees."""
