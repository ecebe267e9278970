"""facyl: fast cylinder detection (Figueiredo et al., RAS 2019) for numpy and Open3D.

Arrays are float32 or float64 of shape (N, 3) (frames: (H, W, 3)), metres; NaN rows are
missing points. Functions release the GIL while they compute.
"""
from typing import Any, Dict, List, Optional, Sequence, Tuple

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
    def inlier_ratio(self) -> float: ...
    @property
    def confidence(self) -> float: ...
    @property
    def rms_error(self) -> float: ...
    @property
    def angular_coverage(self) -> float: ...
    @property
    def coefficients(self) -> npt.NDArray[np.float32]:
        """PCL's SACMODEL_CYLINDER layout: point on axis (3), axis direction (3), radius."""
        ...

def fit_cylinders(
    points: npt.NDArray[np.floating[Any]],
    normals: Optional[npt.NDArray[np.floating[Any]]] = None,
    *,
    radius_limits: Tuple[float, float] = (0.01, 0.25),
    prior: str = "uniform",
    up: Optional[Sequence[float]] = None,
    max_cylinders: int = 1,
    voting: str = "soft-curvature",
    k: int = 16,
    distance_threshold: Optional[float] = None,
    seed: int = 0,
) -> List[Cylinder]: ...

def estimate_normals_curvatures(
    points: npt.NDArray[np.floating[Any]], k: int = 16
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
) -> Dict[str, Any]: ...

def simulate_cylinder(
    *,
    radius: float = 0.3,
    height: float = 1.0,
    axis: Sequence[float] = (0.0, 0.0, 1.0),
    base: Sequence[float] = (0.0, 0.0, 0.0),
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
