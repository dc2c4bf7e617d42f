"""Type stubs of the extension module ``cadmorph._native`` (re-exported by ``cadmorph``).

Points are numpy ``float64`` arrays of shape ``(n, 3)``, C-contiguous. Every deformation
reads them in place (no copy) and returns one new array, or writes into ``out`` (``out=points``
morphs in place). Bad arguments raise ``TypeError`` (not an array, another dtype) or
``ValueError`` (shape, contiguity, NaN/inf) naming the argument.
"""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

Points = npt.NDArray[np.float64]
"""An (n, 3) float64 C-contiguous array."""
Vec3 = Union[Sequence[float], npt.NDArray[np.float64]]
StrPath = Union[str, PathLike]

class ParameterError(ValueError):
    """A parameter file (PyGeM .prm or TOML) or parameter value is invalid."""

    path: Optional[str]
    """The file, or None for text or values given in Python."""
    line: Optional[int]
    """The 1-based line of the problem, when it is in a file or text."""

class CadFileError(ValueError):
    """An IGES/STEP file does not read, or a model cannot be morphed or saved."""

    path: Optional[str]
    """The file, or None."""
    line: Optional[int]
    """The 1-based line of the problem in the file, when known."""
    entity: Optional[str]
    """The entity concerned: IGES ``"DE 5"``, STEP ``"#12"``, or None."""

class _Deformation:
    def deform(self, points: Points, out: Optional[Points] = None) -> Points:
        """The deformed copy of ``points``; with ``out``, written there and ``out`` returned."""
    def __call__(self, points: Points, out: Optional[Points] = None) -> Points:
        """Same as :meth:`deform`."""
    def then(self, next: "_Deformation") -> "Composed":
        """This deformation followed by ``next``."""

class Ffd(_Deformation):
    """Free-form deformation on an L×M×N Bernstein lattice (PyGeM's ``FFD``).

    Points outside the closed box do not move; points whose unit-box coordinates lie
    within ``face_tol`` of the box move like their neighbours inside (``face_tol=0`` is
    PyGeM's strict test).
    """

    def __init__(
        self,
        n_control_points: Tuple[int, int, int] = (2, 2, 2),
        box_origin: Optional[Vec3] = None,
        box_length: Optional[Vec3] = None,
        rot_angle: Optional[Vec3] = None,
        face_tol: float = 1e-12,
    ) -> None: ...
    @property
    def n_control_points(self) -> Tuple[int, int, int]:
        """Lattice size (L, M, N)."""
    box_origin: npt.NDArray[np.float64]
    """Box origin (lattice node (0, 0, 0), centre of rotation)."""
    box_length: npt.NDArray[np.float64]
    """Box lengths along the rotated axes."""
    rot_angle: npt.NDArray[np.float64]
    """Rotation angles about x, y, z in degrees (R = Rx·Ry·Rz)."""
    mu_x: npt.NDArray[np.float64]
    """Displacements along the box x axis, (L, M, N), in box lengths (a copy; assign to change)."""
    mu_y: npt.NDArray[np.float64]
    """Displacements along the box y axis, (L, M, N)."""
    mu_z: npt.NDArray[np.float64]
    """Displacements along the box z axis, (L, M, N)."""
    @property
    def face_tol(self) -> float:
        """Unit-box tolerance of the box faces."""
    def control_points(self, deformed: bool = True) -> Points:
        """The lattice control points, (L·M·N, 3), C order of (i, j, k)."""
    def jacobian(self, point: Vec3) -> Optional[npt.NDArray[np.float64]]:
        """∂φ/∂x at ``point``, (3, 3)."""
    def to_prm(self) -> str:
        """The PyGeM ``.prm`` text."""
    def to_toml(self) -> str:
        """The TOML form."""
    def write_parameters(self, path: StrPath) -> None:
        """Write TOML (``.toml``) or PyGeM ``.prm`` (any other name)."""
    @staticmethod
    def from_prm(text: str) -> "Ffd":
        """Read an FFD ``.prm`` text (``ParameterError`` with ``line`` when it does not read)."""

class Rbf(_Deformation):
    """RBF interpolation of control-point displacements (PyGeM's ``RBF``), solved on construction."""

    def __init__(
        self,
        original_control_points: Points,
        deformed_control_points: Points,
        kernel: str = "thin_plate_spline",
        radius: float = 0.5,
        k: Optional[int] = None,
    ) -> None: ...
    @property
    def kernel(self) -> str:
        """The kernel name."""
    @property
    def radius(self) -> float:
        """The scaling (or support) radius."""
    @property
    def k(self) -> Optional[int]:
        """The power of thin_plate_spline / polyharmonic_spline."""
    @property
    def original_control_points(self) -> Points:
        """Control points before the deformation."""
    @property
    def deformed_control_points(self) -> Points:
        """Control points after the deformation."""
    @property
    def condition(self) -> float:
        """1-norm condition estimate of the solved system."""
    def pygem_weights(self) -> Points:
        """The weights in PyGeM's layout, (n + 4, 3)."""
    def jacobian(self, point: Vec3) -> Optional[npt.NDArray[np.float64]]:
        """∂φ/∂x at ``point``, or None where the kernel has a corner."""
    def to_prm(self) -> str:
        """The PyGeM ``.prm`` text."""
    def to_toml(self) -> str:
        """The TOML form."""
    def write_parameters(self, path: StrPath) -> None:
        """Write TOML (``.toml``) or PyGeM ``.prm``."""
    @staticmethod
    def from_prm(text: str) -> "Rbf":
        """Read an RBF ``.prm`` text and solve it."""

class Idw(_Deformation):
    """Inverse distance weighting (``variant="paper"``, or ``"pygem"`` for PyGeM's ``IDW``)."""

    def __init__(
        self,
        original_control_points: Points,
        deformed_control_points: Points,
        power: float = 2.0,
        variant: str = "paper",
        cutoff: Optional[float] = None,
    ) -> None: ...
    @property
    def variant(self) -> str:
        """"paper" or "pygem"."""
    @property
    def power(self) -> float:
        """The power."""
    @property
    def cutoff(self) -> Optional[float]:
        """The cutoff radius (paper variant), or None."""
    @property
    def original_control_points(self) -> Points:
        """Control points before the deformation."""
    @property
    def deformed_control_points(self) -> Points:
        """Control points after the deformation."""
    def jacobian(self, point: Vec3) -> Optional[npt.NDArray[np.float64]]:
        """∂φ/∂x at ``point``, or None where it does not exist."""
    def to_prm(self) -> str:
        """The PyGeM ``.prm`` text (pygem variant only)."""
    def to_toml(self) -> str:
        """The TOML form."""
    def write_parameters(self, path: StrPath) -> None:
        """Write TOML (``.toml``) or PyGeM ``.prm``."""
    @staticmethod
    def from_prm(text: str) -> "Idw":
        """Read an IDW ``.prm`` text (the pygem variant)."""

class Affine(_Deformation):
    """An affine map x ↦ A x + t."""

    def __init__(self, matrix: Optional[Any] = None, translation: Optional[Vec3] = None) -> None: ...
    @staticmethod
    def translation(t: Vec3) -> "Affine":
        """A translation by ``t``."""
    @staticmethod
    def scaling(s: Vec3) -> "Affine":
        """A scaling about the origin."""
    @staticmethod
    def rotation(angles_deg: Vec3) -> "Affine":
        """A rotation about the origin, degrees about x, y, z (R = Rx·Ry·Rz)."""
    @property
    def matrix(self) -> npt.NDArray[np.float64]:
        """The linear part A, (3, 3)."""
    @property
    def translation_vector(self) -> npt.NDArray[np.float64]:
        """The translation t."""
    def inverse(self) -> Optional["Affine"]:
        """The inverse map, or None when A is singular."""

class Composed(_Deformation):
    """Deformations applied one after the other."""

    def __len__(self) -> int:
        """The number of stages."""
    def jacobian(self, point: Vec3) -> Optional[npt.NDArray[np.float64]]:
        """∂φ/∂x by the chain rule, or None when a stage has none."""

class FromFunction(_Deformation):
    """A deformation given by a Python function ``f(points) -> points`` on (n, 3) arrays."""

    def __init__(self, func: Callable[[Points], Any]) -> None: ...

class Model:
    """An IGES or STEP file as NURBS faces and the edges they share."""

    @property
    def format(self) -> str:
        """"iges" or "step"."""
    @property
    def unit(self) -> str:
        """The length unit's name."""
    @property
    def size(self) -> float:
        """The model size (bounding-box diagonal of the control points)."""
    @property
    def path(self) -> Optional[str]:
        """The file it was opened from."""
    @property
    def faces(self) -> List[Dict[str, Any]]:
        """One dict per face: face, surface, kind, u_degree, v_degree, n_u, n_v, rational, analytic, trimmed, reversed."""
    @property
    def skipped(self) -> List[Dict[str, Any]]:
        """Faces that could not be converted: entity, reason."""
    @property
    def edges(self) -> List[Dict[str, Any]]:
        """Shared edges: kind ("iso"/"trim"), faces, sides or entities."""
    def control_points(self, index: int) -> Points:
        """Control points of face ``index``, (n_u·n_v, 3), u-major."""
    def weights(self, index: int) -> npt.NDArray[np.float64]:
        """Weights of face ``index`` (1 for non-rational)."""
    def seams(self, samples: int = 200) -> List[Dict[str, Any]]:
        """One dict per shared edge: a, b, edge, length, gap_closest, gap_matched, g1_angle_deg, ..."""
    def seam_report(self, samples: int = 200) -> Dict[str, Any]:
        """The edges and the maxima over them."""
    def morph(
        self,
        deformation: _Deformation,
        refine_tol: Optional[float] = None,
        angle_tol: float = 0.01,
        max_control_points: Optional[int] = None,
        uniform_knots: Optional[int] = None,
        repair: bool = False,
    ) -> Dict[str, Any]:
        """Morph every face; returns the outcome (control points, faces rewritten, seams before/after)."""
    def verify(self) -> Dict[str, Any]:
        """The written document read back: seams and max_deviation."""
    def save(self, path: StrPath) -> None:
        """Write to ``path``, format from the extension (.igs/.iges, .stp/.step)."""
    def to_bytes(self) -> bytes:
        """The document's bytes."""
    def __len__(self) -> int:
        """The number of faces."""

def open(path: StrPath) -> Model:
    """Open an IGES or STEP file."""

def from_bytes(data: bytes) -> Model:
    """A model from a file's bytes."""

def read_parameters(path: StrPath) -> Union[Ffd, Rbf, Idw]:
    """Read a parameter file: TOML (``.toml``) or PyGeM ``.prm``."""

def parameters_from_str(text: str, toml: bool = False) -> Union[Ffd, Rbf, Idw]:
    """Parse parameter text (``.prm`` by default)."""

def compose(*deformations: _Deformation) -> Composed:
    """``compose(a, b)`` applies ``a`` then ``b``."""

def ffd_with_mu(
    n_control_points: Tuple[int, int, int],
    box_origin: Vec3,
    box_length: Vec3,
    rot_angle: Vec3,
    mu_x: npt.NDArray[np.float64],
    mu_y: npt.NDArray[np.float64],
    mu_z: npt.NDArray[np.float64],
    face_tol: float,
) -> Ffd:
    """An Ffd from its box and three (L, M, N) displacement arrays."""

def set_num_threads(n: Optional[int] = None) -> bool:
    """Size rayon's pool before the first morph; False when it already exists."""

def num_threads() -> int:
    """The number of rayon threads."""
