"""PyGeM's class and attribute names on cadmorph's Rust implementation.

A PyGeM script runs with one changed import::

    import cadmorph.pygem as pygem          # was: import pygem
    from cadmorph.pygem import FFD, RBF, IDW, CustomDeformation
    from cadmorph.pygem.cad import FFD      # CAD files, no pythonocc needed

The classes keep PyGeM's attributes (``box_origin``, ``box_length``, ``rot_angle``,
``array_mu_x/y/z``, ``n_control_points``, ``original_control_points``, ...) as plain
numpy arrays a script may edit in place; each call builds the Rust deformation from
them and applies it. The numbers are PyGeM's to 1e-10 on PyGeM's own test data.

Where cadmorph differs from PyGeM, on purpose:

* **FFD box faces.** PyGeM moves a point only when its unit-box coordinates lie in
  ``[0, 1]`` exactly, so rounding may leave points on a face behind (PyGeM issue 272).
  This layer keeps PyGeM's strict test (``FFD.face_tol = 0.0``) for the same numbers;
  cadmorph's own :class:`cadmorph.Ffd` counts points within ``1e-12`` (unit-box
  coordinates) as on the box. Set ``ffd.face_tol = 1e-12`` to get that here.
* **IDW.** PyGeM's ``IDW`` does not compute what its docstring says: it measures the
  distance in the Minkowski ``power``-norm and weighs by ``1/d``. This layer computes
  exactly that (cadmorph's ``Idw(..., variant="pygem")``); cadmorph's default
  ``variant="paper"`` is the paper's ``d**-power`` with Euclidean distance.
* **RBF.** The system is solved by a stable factorisation and refused with
  :class:`cadmorph.ParameterError` when it is singular or ill-conditioned (PyGeM
  returns numerical noise, e.g. a Gaussian of radius 0.5 on 1000 random centres).
* **Bad input.** Points with NaN, arrays of another shape or dtype raise
  ``ValueError``/``TypeError`` naming the argument (PyGeM computes on).
* ``dtype`` other than ``fp64`` is not offered: the Rust implementation is float64.
* ``RBF.basis`` is the kernel's name (PyGeM: the kernel function from ``RBFFactory``);
  ``RBF.weights`` is computed by the Rust solve, in PyGeM's layout.
* ``pygem.cad`` needs no pythonocc and takes no ``TopoDS_Shape``: it takes a file name or a
  :class:`cadmorph.Model` (see :mod:`cadmorph.pygem.cad`).
"""

import copy as _copy
import hashlib as _hashlib
import os as _os

import numpy as _np

from .. import _native

__all__ = ["Deformation", "FFD", "RBF", "IDW", "CustomDeformation"]

_CUBE = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0],
         [0.0, 1.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]]


def _points(a, name):
    """``a`` as a C-contiguous float64 array: the same array when it already is one (no copy).

    ``name`` is the argument the Rust side names when the shape or values are wrong.
    """
    del name  # the native call names "points"; PyGeM's argument is the only one
    return _np.ascontiguousarray(a, dtype=_np.float64)


def _check_filename(filename):
    if not isinstance(filename, str):
        raise TypeError("filename must be a string")


class Deformation:
    """Base class of the deformations (PyGeM's ``pygem.Deformation``): ``__call__(src_pts)``."""

    def __call__(self, src_pts):
        """Deform the (n, 3) points ``src_pts``; returns a new array."""
        raise NotImplementedError("a Deformation subclass defines __call__")

    def native(self):
        """The :mod:`cadmorph` deformation these attributes describe."""
        raise NotImplementedError


class FFD(Deformation):
    """Free Form Deformation on a Bernstein lattice, PyGeM's ``FFD``.

    :param list n_control_points: control points in x, y, z (default ``[2, 2, 2]``).

    Attributes, as in PyGeM: ``box_length``, ``box_origin``, ``rot_angle`` (degrees),
    ``n_control_points``, ``array_mu_x``, ``array_mu_y``, ``array_mu_z`` (displacements
    in units of the box length, arrays of shape ``n_control_points``), and
    ``face_tol`` (0.0: PyGeM's strict box test; see the module docs).

    >>> from cadmorph.pygem import FFD
    >>> ffd = FFD()
    >>> ffd.read_parameters('samples/pygem/parameters_test_ffd_sphere.prm')  # doctest: +SKIP
    >>> new_mesh_points = ffd(original_mesh_points)                           # doctest: +SKIP
    """

    reference_frame = _np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])

    def __init__(self, n_control_points=None):
        self.conversion_unit = 1.0
        self.box_length = _np.array([1.0, 1.0, 1.0])
        self.box_origin = _np.array([0.0, 0.0, 0.0])
        self.rot_angle = _np.array([0.0, 0.0, 0.0])
        self.face_tol = 0.0
        self.array_mu_x = None
        self.array_mu_y = None
        self.array_mu_z = None
        if n_control_points is None:
            n_control_points = [2, 2, 2]
        self.n_control_points = n_control_points

    @property
    def n_control_points(self):
        """The number of control points in x, y and z (numpy array); setting it resets the weights."""
        return self._n_control_points

    @n_control_points.setter
    def n_control_points(self, npts):
        self._n_control_points = _np.array(npts)
        self.array_mu_x = _np.zeros(self.n_control_points)
        self.array_mu_y = _np.zeros(self.n_control_points)
        self.array_mu_z = _np.zeros(self.n_control_points)

    def native(self):
        """The :class:`cadmorph.Ffd` of the current attributes."""
        n = tuple(int(v) for v in self.n_control_points)
        mus = []
        for name in ("array_mu_x", "array_mu_y", "array_mu_z"):
            mu = _np.asarray(getattr(self, name), dtype=_np.float64)
            if mu.shape != n:
                raise ValueError(f"{name} must have shape {n} (n_control_points), got {mu.shape}")
            mus.append(mu)
        return _native.ffd_with_mu(n, _np.asarray(self.box_origin, dtype=float), _np.asarray(self.box_length, dtype=float),
                                   _np.asarray(self.rot_angle, dtype=float), mus[0], mus[1], mus[2], float(self.face_tol))

    @property
    def rotation_matrix(self):
        """The rotation matrix R = Rx·Ry·Rz of ``rot_angle`` (degrees), as PyGeM's."""
        return _np.asarray(_native.Affine.rotation(_np.asarray(self.rot_angle, dtype=float)).matrix)

    @property
    def position_vertices(self):
        """The origin and the three box vertices next to it, (4, 3)."""
        return self.box_origin + _np.vstack([_np.zeros((1, 3)), self.rotation_matrix.dot(_np.diag(self.box_length)).T])

    def reset_weights(self):
        """Set all displacements to zero."""
        self.array_mu_x.fill(0.0)
        self.array_mu_y.fill(0.0)
        self.array_mu_z.fill(0.0)

    def read_parameters(self, filename='parameters.prm'):
        """Read a PyGeM FFD ``.prm`` file (written with the defaults when it does not exist, as PyGeM does)."""
        _check_filename(filename)
        if not _os.path.isfile(filename):
            self.write_parameters(filename)
            return
        with open(filename, encoding="utf-8", errors="surrogateescape") as f:
            text = f.read()
        try:
            ffd = _native.Ffd.from_prm(text)
        except _native.ParameterError as e:
            raise _native.ParameterError(f"{filename}: {e}") from e
        self._n_control_points = _np.array(ffd.n_control_points)
        self.box_length = _np.array(ffd.box_length)
        self.box_origin = _np.array(ffd.box_origin)
        self.rot_angle = _np.array(ffd.rot_angle)
        self.array_mu_x = _np.array(ffd.mu_x)
        self.array_mu_y = _np.array(ffd.mu_y)
        self.array_mu_z = _np.array(ffd.mu_z)

    def write_parameters(self, filename='parameters.prm'):
        """Write the parameters as a PyGeM ``.prm`` file (byte for byte what PyGeM writes)."""
        _check_filename(filename)
        text = self.native().to_prm()
        with open(filename, "w") as f:
            f.write(text)

    def __str__(self):
        string = ""
        string += 'conversion_unit = {}\n'.format(self.conversion_unit)
        string += 'n_control_points = {}\n\n'.format(self.n_control_points)
        string += 'box_length = {}\n'.format(self.box_length)
        string += 'box_origin = {}\n'.format(self.box_origin)
        string += 'rot_angle  = {}\n'.format(self.rot_angle)
        string += '\narray_mu_x =\n{}\n'.format(self.array_mu_x)
        string += '\narray_mu_y =\n{}\n'.format(self.array_mu_y)
        string += '\narray_mu_z =\n{}\n'.format(self.array_mu_z)
        string += '\nrotation_matrix = \n{}\n'.format(self.rotation_matrix)
        string += '\nposition_vertices = {}\n'.format(self.position_vertices)
        return string

    def control_points(self, deformed=True):
        """The lattice control points (by row, C order of (i, j, k)), deformed or not."""
        return self.native().control_points(deformed)

    def reflect(self, axis=0, in_place=True):
        """Reflect the lattice along ``axis`` (0, 1, 2) about the face opposite the origin.

        The lattice gets ``2n - 1`` control points along ``axis`` and twice the box length;
        the displacements along ``axis`` are mirrored. The symmetry plane must not be
        displaced along ``axis`` (RuntimeError otherwise), as in PyGeM. Returns the new
        FFD when ``in_place`` is False.
        """
        if axis not in (0, 1, 2):
            raise ValueError("The axis has to be 0, 1, or 2. Current value {}.".format(axis))
        mus = (self.array_mu_x, self.array_mu_y, self.array_mu_z)
        plane = [slice(None)] * 3
        plane[axis] = -1
        if _np.count_nonzero(mus[axis][tuple(plane)]) != 0:
            raise RuntimeError(
                "If you want to reflect the FFD bounding box along axis {} you can not diplace the control "
                "points in the symmetry plane along that axis.".format(axis))
        target = self if in_place else _copy.deepcopy(self)
        target._n_control_points[axis] = 2 * target._n_control_points[axis] - 1
        target.box_length[axis] *= 2
        reflection = _np.ones(3)
        reflection[axis] = -1
        indices = [slice(None)] * 3
        indices[axis] = slice(1, None)
        indices = tuple(indices)
        for c, name in enumerate(("array_mu_x", "array_mu_y", "array_mu_z")):
            mu = getattr(target, name)
            setattr(target, name, _np.append(mu, reflection[c] * _np.flip(mu, axis)[indices], axis=axis))
        return None if in_place else target

    def __call__(self, src_pts):
        """Deform the (n, 3) points ``src_pts`` (a new array, as PyGeM)."""
        return self.native()(_points(src_pts, "src_pts"))


class RBF(Deformation):
    """Radial Basis Function interpolation, PyGeM's ``RBF``.

    :param original_control_points: (n, 3) control points before the deformation
        (default: the 8 corners of the unit cube).
    :param deformed_control_points: (n, 3) after (default: the same).
    :param str func: the basis function name (``gaussian_spline`` by default, or
        ``multi_quadratic_biharmonic_spline``, ``inv_multi_quadratic_biharmonic_spline``,
        ``thin_plate_spline``, ``beckert_wendland_c2_basis``, ``polyharmonic_spline``, and
        cadmorph's ``wendland_c0/c2/c4``).
    :param float radius: the scaling radius (default 0.5).
    :param dict extra_parameter: ``{'k': k}`` for ``thin_plate_spline`` and ``polyharmonic_spline``.
    """

    def __init__(self, original_control_points=None, deformed_control_points=None, func='gaussian_spline',
                 radius=0.5, extra_parameter=None, dtype='fp64'):
        if str(dtype).lower() not in ('fp64', 'float64'):
            raise ValueError(f"dtype: cadmorph computes in float64 only, got {dtype!r}")
        self.basis = func
        self.radius = radius
        self.original_control_points = _np.array(_CUBE if original_control_points is None else original_control_points,
                                                 dtype=_np.float64)
        self.deformed_control_points = _np.array(_CUBE if deformed_control_points is None else deformed_control_points,
                                                 dtype=_np.float64)
        self.extra = extra_parameter if extra_parameter else dict()
        self._cache = (None, None)

    @property
    def n_control_points(self):
        """Total number of control points."""
        return self.original_control_points.shape[0]

    def _key(self):
        h = _hashlib.sha1()
        for a in (self.original_control_points, self.deformed_control_points):
            h.update(_np.ascontiguousarray(a, dtype=_np.float64).tobytes())
        return (self.basis, float(self.radius), tuple(sorted(self.extra.items())), h.hexdigest())

    def native(self):
        """The solved :class:`cadmorph.Rbf` of the current attributes (kept until they change)."""
        key = self._key()
        if self._cache[0] != key:
            extra = dict(self.extra)
            k = extra.pop('k', None)
            if extra:
                raise ValueError(f"extra_parameter: unknown keys {sorted(extra)} (only 'k' is known)")
            rbf = _native.Rbf(_points(self.original_control_points, "original_control_points"),
                              _points(self.deformed_control_points, "deformed_control_points"),
                              kernel=self.basis, radius=float(self.radius), k=None if k is None else int(k))
            self._cache = (key, rbf)
        return self._cache[1]

    @property
    def weights(self):
        """The weights in PyGeM's layout, (n + 4, 3)."""
        return self.native().pygem_weights()

    def compute_weights(self):
        """Solve the system now (PyGeM computes its weights here)."""
        self.native()

    def read_parameters(self, filename='parameters_rbf.prm'):
        """Read a PyGeM RBF ``.prm`` file (written with the defaults when it does not exist, as PyGeM does)."""
        _check_filename(filename)
        if not _os.path.isfile(filename):
            self.write_parameters(filename)
            return
        with open(filename, encoding="utf-8", errors="surrogateescape") as f:
            text = f.read()
        try:
            rbf = _native.Rbf.from_prm(text)
        except _native.ParameterError as e:
            raise _native.ParameterError(f"{filename}: {e}") from e
        self.basis = rbf.kernel
        self.radius = rbf.radius
        self.extra = {} if rbf.k is None or 'k' not in text else {'k': rbf.k}
        self.original_control_points = _np.array(rbf.original_control_points)
        self.deformed_control_points = _np.array(rbf.deformed_control_points)
        self._cache = (self._key(), rbf)

    def write_parameters(self, filename='parameters_rbf.prm'):
        """Write the parameters as a PyGeM RBF ``.prm`` file."""
        _check_filename(filename)
        with open(filename, "w") as f:
            f.write(self.native().to_prm())

    def __call__(self, src_pts):
        """Deform the (n, 3) points ``src_pts`` (a new array)."""
        return self.native()(_points(src_pts, "src_pts"))


class IDW(Deformation):
    """Inverse Distance Weighting, PyGeM's ``IDW`` (its variant: Minkowski distance, weight 1/d).

    :param original_control_points: (n, 3) before (default: the unit cube's corners).
    :param deformed_control_points: (n, 3) after (default: the same).
    :param int power: the order of the Minkowski norm (default 2).
    """

    def __init__(self, original_control_points=None, deformed_control_points=None, power=2):
        self.original_control_points = _np.array(_CUBE if original_control_points is None else original_control_points,
                                                 dtype=_np.float64)
        self.deformed_control_points = _np.array(_CUBE if deformed_control_points is None else deformed_control_points,
                                                 dtype=_np.float64)
        self.power = power

    def native(self):
        """The :class:`cadmorph.Idw` (``variant="pygem"``) of the current attributes."""
        return _native.Idw(_points(self.original_control_points, "original_control_points"),
                           _points(self.deformed_control_points, "deformed_control_points"),
                           power=float(self.power), variant="pygem")

    def read_parameters(self, filename):
        """Read a PyGeM IDW ``.prm`` file."""
        _check_filename(filename)
        with open(filename, encoding="utf-8", errors="surrogateescape") as f:
            text = f.read()
        try:
            idw = _native.Idw.from_prm(text)
        except _native.ParameterError as e:
            raise _native.ParameterError(f"{filename}: {e}") from e
        self.power = int(idw.power)
        self.original_control_points = _np.array(idw.original_control_points)
        self.deformed_control_points = _np.array(idw.deformed_control_points)

    def write_parameters(self, filename):
        """Write the parameters as a PyGeM IDW ``.prm`` file (byte for byte what PyGeM writes)."""
        _check_filename(filename)
        with open(filename, "w") as f:
            f.write(self.native().to_prm())

    def __call__(self, src_pts):
        """Deform the (n, 3) points ``src_pts`` (a new array)."""
        return self.native()(_points(src_pts, "src_pts"))


class CustomDeformation(Deformation):
    """A deformation given by a function, PyGeM's ``CustomDeformation``.

    ``func`` maps an (n, 3) array to an (n, 3) array; when it raises on the whole array it
    is called point by point (``func(point) -> [x, y, z]``), as PyGeM does.
    """

    def __init__(self, func):
        self._func = func

        def vectorised(points):
            try:
                out = func(points)
            except Exception:
                out = [func(pt) for pt in points]
            return _np.ascontiguousarray(out, dtype=_np.float64).reshape(-1, 3)

        self._native = _native.FromFunction(vectorised)

    def native(self):
        """The :class:`cadmorph.FromFunction` of this function."""
        return self._native

    def __call__(self, src_pts):
        """Deform the (n, 3) points ``src_pts`` (a new array)."""
        return self._native(_points(src_pts, "src_pts"))
