"""Type stubs of garnet's native module (``garnet._garnet``). Shapes in brackets; metres."""

from os import PathLike
from pathlib import Path
from typing import Any, Dict, List, Literal, Mapping, Optional, Union

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

__version__: str

StrPath = Union[str, PathLike[str]]
F32 = npt.NDArray[np.float32]
U32 = npt.NDArray[np.uint32]
PoseKind = Literal["walk", "yoga", "dance", "any"]
SkinningName = Literal["dqs", "lbs"]

class GarnetError(Exception):
    """An error of garnet (a damaged file, a drape that failed, ...), with the message the
    ``garnet`` command line prints."""

class Pose:
    """A body pose, or the recipe of one: clip frames are retargeted onto, and procedural
    poses drawn against, the body they are applied to (``Body(..., pose=...)``); the
    body's ``.pose`` is then the concrete pose."""

    @staticmethod
    def rest() -> Pose:
        """The rest A-pose."""
    @staticmethod
    def tpose() -> Pose:
        """The T-pose (arms horizontal)."""
    @staticmethod
    def from_amc(amc: StrPath, frame: int = 0, asf: Optional[StrPath] = None) -> Pose:
        """Frame ``frame`` (0-based) of a CMU AMC clip; skeleton ``asf`` or SUBJECT.asf
        beside the clip. Raises FileNotFoundError, ValueError (frame past the clip)."""
    @staticmethod
    def from_bvh(bvh: StrPath, frame: int = 0) -> Pose:
        """Frame ``frame`` (0-based) of a CMU-style BVH clip."""
    @staticmethod
    def procedural(seed: int, kind: PoseKind = "any") -> Pose:
        """A procedural pose drawn from ``seed`` (self-intersecting draws rejected)."""
    @staticmethod
    def from_arrays(rotations: ArrayLike, root_translation: Optional[ArrayLike] = None) -> Pose:
        """A concrete pose: ``rotations`` [B,4] bone-local quaternions (x, y, z, w),
        ``root_translation`` [3] metres."""
    @property
    def description(self) -> str:
        """The pose in words ("procedural walk 4", "02_01.amc frame 30")."""
    @property
    def rotations(self) -> F32:
        """float32 [B,4] (x, y, z, w) of a concrete pose; ValueError for a recipe."""
    @property
    def root_translation(self) -> F32:
        """float32 [3] metres of a concrete pose; ValueError for a recipe."""

class Body:
    """A body: a shape (phenotype) in a pose."""

    def __init__(
        self,
        phenotype: Optional[Mapping[str, float]] = None,
        pose: Optional[Pose] = None,
        skinning: SkinningName = "dqs",
    ) -> None:
        """``phenotype``: gender, age, muscle, weight, height, proportions, cupsize,
        firmness in [0, 1], race shares african, asian, caucasian (normalised); keys left
        out keep the default (0.5, equal shares). ValueError for an unknown key, NaN or a
        value outside [0, 1]."""
    @staticmethod
    def random(seed: int, pose: Optional[Pose] = None, skinning: SkinningName = "dqs") -> Body:
        """A random realistic adult drawn from ``seed`` (``garnet drape --random-shape``)."""
    def with_pose(self, pose: Pose, skinning: Optional[SkinningName] = None) -> Body:
        """The same shape in another pose."""
    @property
    def vertices(self) -> F32:
        """float32 [V,3]: the posed body, metres (y up)."""
    @property
    def faces(self) -> U32:
        """uint32 [F,3]: the body's triangles."""
    @property
    def rest_vertices(self) -> F32:
        """float32 [V,3]: the shaped body in its rest A-pose, metres."""
    @property
    def joints(self) -> F32:
        """float32 [B,3]: posed joints (bone heads), metres, in ``bone_names`` order."""
    @property
    def bone_names(self) -> List[str]: ...
    @property
    def height(self) -> float:
        """Standing height of the rest mesh, metres."""
    @property
    def phenotype(self) -> Dict[str, float]: ...
    @property
    def pose(self) -> Pose:
        """The concrete pose the body is in."""
    @property
    def skinning(self) -> str: ...

class DrapeResult:
    """One draped garment and the posed body it lies on."""

    @property
    def vertices(self) -> F32:
        """float32 [N,3]: the draped garment, metres."""
    @property
    def faces(self) -> U32:
        """uint32 [F,3]: the garment's triangles."""
    @property
    def body_vertices(self) -> F32:
        """float32 [V,3]: the posed body the garment was draped on, metres."""
    @property
    def body_faces(self) -> U32: ...
    @property
    def pose(self) -> Pose:
        """The pose draped (after the limb clearance)."""
    @property
    def kind(self) -> str: ...
    @property
    def pushed_out(self) -> int:
        """Vertices the push-out moved (0 with raw=True)."""
    @property
    def timings(self) -> Dict[str, float]:
        """Milliseconds: warp_ms, network_ms, push_out_ms, collider_ms."""

class Draper:
    """A trained GarNet model (``.garnet``) on the CPU."""

    def __init__(self, path: StrPath) -> None:
        """Raises FileNotFoundError (missing) or GarnetError (damaged, other format)."""
    def drape(self, body: Body, raw: bool = False, keep_pose: bool = False) -> DrapeResult:
        """Drapes the garment on ``body`` as ``garnet drape`` does: limbs cleared out of
        the body (unless ``keep_pose``), vertices inside the body pushed out (unless
        ``raw``)."""
    @property
    def kind(self) -> str: ...
    @property
    def method(self) -> str: ...
    @property
    def path(self) -> Path: ...
    @property
    def template(self) -> Template: ...

class Template:
    """A garment template (``.garment``) fitted on the template body."""

    def __init__(self, path: StrPath) -> None: ...
    @staticmethod
    def make(kind: Literal["tshirt", "sweater", "jeans"], edge: float = 0.01, **cut: float) -> Template:
        """Builds a template remeshed to edges of about ``edge`` metres (0.004 to 0.08);
        ``cut``: body_length, sleeve_length, ease, neckline_depth, waist_height,
        leg_length, flare, bridge, thigh (metres)."""
    def save(self, path: StrPath) -> None: ...
    @property
    def kind(self) -> str: ...
    @property
    def edge_length(self) -> float: ...
    @property
    def vertices(self) -> F32:
        """float32 [N,3] on the template body, metres."""
    @property
    def faces(self) -> U32: ...

class SimulationResult:
    """A finished simulated drape."""

    @property
    def vertices(self) -> F32:
        """float32 [N,3]: the draped garment, metres."""
    @property
    def faces(self) -> U32: ...
    @property
    def body_vertices(self) -> F32: ...
    @property
    def body_faces(self) -> U32: ...
    @property
    def vertex_strain(self) -> F32:
        """float32 [N]: the largest edge strain at each vertex."""
    @property
    def pose(self) -> Pose: ...
    @property
    def stats(self) -> Dict[str, Any]:
        """The drape's statistics (``garnet simulate --stats``)."""
    @property
    def summary(self) -> str: ...

def simulate(
    template: Union[Template, StrPath],
    body: Body,
    *,
    keep_pose: bool = False,
    skinning: Optional[SkinningName] = None,
    simulator: Optional[Union[Mapping[str, Any], StrPath]] = None,
    max_settle_steps: Optional[int] = None,
    max_penetration_mm: Optional[float] = None,
) -> SimulationResult:
    """Drapes ``template`` on ``body`` with the cloth simulator (``garnet simulate``).
    Raises GarnetError when the drape diverges or leaves cloth inside the body."""

class Dataset:
    """A garnet dataset folder as a sequence of dicts of numpy arrays: "body" [V,3],
    "warped" [N,3], "draped" [N,3], "rotations" [B,4], "root_translation" [3],
    "phenotype" [11], "faces" [F,3] (uint32), optional "fitted" [N,3]; "index",
    "garment", "template", "body_index", "split", "pose", "stature_m", "bmi", "stats"."""

    def __init__(
        self,
        dir: StrPath,
        split: Optional[str] = None,
        garment: Optional[str] = None,
        cache_shards: int = 2,
    ) -> None: ...
    def __len__(self) -> int: ...
    def __getitem__(self, i: int) -> Dict[str, Any]: ...
    def sample(self, index: int) -> Dict[str, Any]:
        """The sample of dataset index ``index`` (its "index")."""
    @property
    def indices(self) -> List[int]: ...
    @property
    def splits(self) -> List[str]: ...
    @property
    def garments(self) -> List[str]: ...
    @property
    def dir(self) -> Path: ...
    @property
    def body_faces(self) -> U32:
        """uint32 [F,3]: the body's triangles."""
    def template(self, id: str) -> Template: ...

def e_dist(gt: ArrayLike, pred: ArrayLike) -> float:
    """E_dist in cm."""

def e_norm(gt: ArrayLike, pred: ArrayLike, faces: ArrayLike) -> float:
    """E_norm in degrees."""

def shipped_models_dir() -> Path: ...
def shipped_models() -> List[Path]: ...
