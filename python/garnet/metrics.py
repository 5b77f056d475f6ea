"""The GarNet paper's error metrics, in the units its tables report."""

from ._garnet import e_dist, e_norm

__all__ = ["e_dist", "e_norm"]
