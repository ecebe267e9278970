"""facyl: fast cylinder detection (Figueiredo et al., RAS 2019) for numpy and Open3D.

Arrays are float32 or float64 of shape (N, 3) (frames: (H, W, 3); float16 raises TypeError:
convert it), or Open3D Vector3dVector;
metres (fit_cylinders: units="mm" converts); NaN rows are missing points. Keywords are the
tools' option names with '_' for '-', with their defaults. Functions release the GIL while
they compute.
"""
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Cylinder:
    """A fitted finite cylinder (metres)."""
    @property
    def point_on_axis(self) -> npt.NDArray[np.float32]: ...
    @property
    def axis(self) -> npt.NDArray[np.float32]: ...
    @property
    def radius(self) -> float: ...
    @property
    def height(self) -> float: ...
    @property
    def base(self) -> npt.NDArray[np.float32]: ...
    @property
    def top(self) -> npt.NDArray[np.float32]: ...
    @property
    def inliers(self) -> npt.NDArray[np.int64]: ...
    @property
    def n_inliers(self) -> int: ...
    @property
    def inlier_ratio(self) -> float: ...
    @property
    def confidence(self) -> float: ...
    @property
    def rms_error(self) -> float: ...
    @property
    def angular_coverage(self) -> float: ...
    def as_dict(self) -> Dict[str, Any]:
        """facyl_fit's fields for this cylinder."""
        ...
    @property
    def coefficients(self) -> npt.NDArray[np.float32]:
        """PCL's SACMODEL_CYLINDER layout: point on axis (3), axis direction (3), radius."""
        ...

def fit_cylinders(
    points: Any,  # (N, 3) float array or open3d.utility.Vector3dVector
    normals: Optional[Any] = None,
    *,
    radius_limits: Union[Tuple[float, float], str, None] = None,  # None: "auto"; (min, max)
    prior: Optional[str] = None,  # None: "vertical" with up, else "uniform"
    up: Optional[Sequence[float]] = None,
    voting: str = "soft-curvature",
    neighbours: int = 16,
    orientations: int = 450,
    accumulators: int = 1,
    distance_threshold: Optional[float] = None,
    max_cylinders: int = 1,
    outward_normals: bool = False,
    any_normal_sign: bool = False,
    point_candidates: int = 3,
    coarse_scale: float = 1.0,
    method: str = "facyl",  # "facyl" | "pcl-ransac"
    seed: int = 0,
    units: str = "auto",  # "auto" | "m" | "mm"
    k: Optional[int] = None,  # old spelling of neighbours
) -> List[Cylinder]: ...

def estimate_normals_curvatures(
    points: Any, neighbours: int = 16, *, k: Optional[int] = None
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.float32],
           npt.NDArray[np.float32]]:
    """(normals, principal_directions, k_max, k_min); k_* are PCL's pc1/pc2 (dimensionless)."""
    ...

def detect(
    points: npt.NDArray[np.floating[Any]],
    colors: Optional[npt.NDArray[np.uint8]] = None,
    *,
    camera: Optional[Sequence[float]] = None,
    up: Optional[Sequence[float]] = None,
    model: str = "default",
    **options: Any,  # facyl_detect's recognizer options, '_' for '-': radius_limits=(0.01, 0.25), ...
) -> Dict[str, Any]:
    """facyl_detect's JSON object as a dict (plus "indices" per object)."""
    ...

def simulate_cylinder(
    *,
    radius: float = 0.05,
    height: float = 0.2,
    axis: Sequence[float] = (0.0, 0.0, 1.0),
    base: Sequence[float] = (0.0, 0.0, 0.8),
    points: int = 900,
    lid_ratio: float = 0.0,
    noise: float = 0.0,
    occlusion: float = 0.0,
    random_axis: bool = False,
    seed: int = 0,
) -> Dict[str, Any]: ...

def render_tabletop_scene(
    *, seed: int = 0, layout: str = "spread", sensor: str = "kinect"
) -> Dict[str, Any]: ...

def render_sequence_frame(
    *,
    seed: int = 0,
    frame: int = 0,
    frames: int = 30,
    layout: str = "cluttered",
    sensor: str = "kinect",
    change: str = "none",  # "none" | "remove" | "add"
    orbit: float = 0.9,
) -> Dict[str, Any]:
    """Frame `frame` of a simulated stream (facyl_synth --sequence): render_tabletop_scene's keys
    plus "sequence" (the change; per frame the camera pose and the object ids present)."""
    ...

class Tracker:
    """Objects and cylinders tracked across the frames of one stream (facyl_detect --track)."""
    def __init__(
        self,
        *,
        camera: Optional[Sequence[float]] = None,
        up: Optional[Sequence[float]] = None,
        model: str = "default",
        track_confirm_hits: int = 2,
        track_max_misses: int = 5,
        track_support_switch_frames: int = 3,
        **options: Any,  # detect()'s recognizer options
    ) -> None: ...
    def update(
        self,
        points: npt.NDArray[np.floating[Any]],
        colors: Optional[npt.NDArray[np.uint8]] = None,
    ) -> Dict[str, Any]:
        """facyl_detect --track's JSON line as a dict (objects with "track_id", "track", "cylinder"
        tracked and "cylinder_frame"; "stream"; "tracks"); ValueError skips the frame."""
        ...
    def skip(self) -> None:
        """A frame that could not be had: counted, the tracks are kept."""
        ...
    def reset(self) -> None:
        """Ends every track; ids go on."""
        ...
    @property
    def tracks(self) -> List[Dict[str, Any]]: ...
    @property
    def frame(self) -> int: ...
