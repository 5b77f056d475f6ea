"""garnet: fast 3D cloth draping after GarNet (Gundogdu et al., ICCV 2019).

Drape garments on bodies with trained GarNet models in milliseconds, simulate them with the
cloth simulator, and read garnet datasets as numpy arrays (or PyTorch tensors).

Units: metres inside; ``garnet.metrics`` reports in cm and degrees. Arrays are float32
``[N, 3]`` points and uint32 ``[F, 3]`` triangles.

>>> import garnet
>>> body = garnet.Body.random(3, pose=garnet.Pose.procedural(4))
>>> draped = garnet.Draper(garnet.shipped_models_dir() / "tshirt-local.garnet").drape(body)
>>> draped.vertices.shape, draped.faces.shape  # doctest: +SKIP
"""

from . import metrics
from ._garnet import (
    Body,
    Dataset,
    Draper,
    DrapeResult,
    GarnetError,
    Pose,
    SimulationResult,
    Template,
    __version__,
    shipped_models,
    shipped_models_dir,
    simulate,
)

__all__ = [
    "Body",
    "Dataset",
    "Draper",
    "DrapeResult",
    "GarnetError",
    "Pose",
    "SimulationResult",
    "Template",
    "__version__",
    "metrics",
    "shipped_models",
    "shipped_models_dir",
    "simulate",
]
