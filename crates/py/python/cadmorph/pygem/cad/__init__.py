"""PyGeM's ``pygem.cad`` on cadmorph: deform IGES/STEP files without pythonocc.

``FFD``, ``RBF``, ``IDW`` and ``CustomDeformation`` have the attributes of their
``cadmorph.pygem`` namesakes and PyGeM's CAD call::

    from cadmorph.pygem.cad import FFD
    ffd = FFD()
    ffd.read_parameters("parameters_test_ffd_iges.prm")
    ffd("input.iges", "output.iges")       # or ffd(model): morphs a cadmorph.Model

Like PyGeM, every control point of every face moves with the point deformation (PyGeM
converts each face to a B-spline surface and moves its poles; so does cadmorph, for
analytic faces too). Unlike PyGeM, the output is the input document with only the moved
entities rewritten, the face trims are traced on the morphed faces, and the knots can be
refined where the morph needs them (``refine_tol``, cadmorph's seam-keeping refinement).

``u_knots_to_add`` / ``v_knots_to_add`` insert evenly spaced knots before the morph, as
PyGeM's do; cadmorph inserts the same number in both directions, so the two must be
equal (or one of them 0). ``t_knots_to_add`` and ``tolerance`` are accepted and unused:
the curves are traced on the morphed faces instead of being moved by their own poles.
"""

from ... import _native
from .. import CustomDeformation as _CustomDeformation
from .. import FFD as _FFD
from .. import IDW as _IDW
from .. import RBF as _RBF

__all__ = ["CADDeformation", "FFD", "RBF", "IDW", "CustomDeformation"]


class CADDeformation:
    """The CAD side of the deformations: ``__call__(obj, dst=None)`` on files or models.

    :param int u_knots_to_add: knots to insert in u on every face before the morph.
    :param int v_knots_to_add: knots to insert in v (must equal ``u_knots_to_add`` when both are given).
    :param int t_knots_to_add: accepted for PyGeM scripts, unused (see the module docs).
    :param float tolerance: accepted for PyGeM scripts, unused.
    :param float refine_tol: cadmorph only: refine so that the seams stay within this gap
        (model units) after the morph; None (default) morphs the control points as they are.
    """

    def __init__(self, u_knots_to_add=0, v_knots_to_add=0, t_knots_to_add=0, tolerance=1e-4, refine_tol=None):
        self.u_knots_to_add = u_knots_to_add
        self.v_knots_to_add = v_knots_to_add
        self.t_knots_to_add = t_knots_to_add
        self.tolerance = tolerance
        self.refine_tol = refine_tol
        self.outcome = None

    @staticmethod
    def read_shape(filename):
        """Open an IGES or STEP file as a :class:`cadmorph.Model`."""
        return _native.open(filename)

    @staticmethod
    def write_shape(filename, shape):
        """Write a :class:`cadmorph.Model` to ``filename`` (format from the extension)."""
        shape.save(filename)

    def _knots(self):
        u, v = int(self.u_knots_to_add), int(self.v_knots_to_add)
        if u and v and u != v:
            raise ValueError(
                f"u_knots_to_add={u} and v_knots_to_add={v}: cadmorph inserts the same number of knots in u and v")
        return max(u, v) or None

    def __call__(self, obj, dst=None):
        """Deform a file (``obj`` a path, written to ``dst``) or a :class:`cadmorph.Model` (returned).

        The outcome (control points, faces rewritten, seams before and after) is kept in
        ``self.outcome``.
        """
        if isinstance(obj, str):
            if dst is None:
                raise ValueError('Source file is provided, but no destination specified')
            model = _native.open(obj)
        elif isinstance(obj, _native.Model):
            model = obj
        else:
            raise TypeError(f"obj must be a file name or a cadmorph.Model, got {type(obj).__name__}")
        self.outcome = model.morph(self.native(), refine_tol=self.refine_tol, uniform_knots=self._knots())
        if isinstance(dst, str):
            model.save(dst)
            return None
        return model


class FFD(CADDeformation, _FFD):
    """Free Form Deformation of CAD files (PyGeM's ``pygem.cad.FFD``)."""

    def __init__(self, n_control_points=None, u_knots_to_add=0, v_knots_to_add=0, t_knots_to_add=0, tolerance=1e-4,
                 refine_tol=None):
        _FFD.__init__(self, n_control_points=n_control_points)
        CADDeformation.__init__(self, u_knots_to_add, v_knots_to_add, t_knots_to_add, tolerance, refine_tol)

    __call__ = CADDeformation.__call__


class RBF(CADDeformation, _RBF):
    """Radial Basis Function deformation of CAD files (PyGeM's ``pygem.cad.RBF``)."""

    def __init__(self, original_control_points=None, deformed_control_points=None, func='gaussian_spline', radius=0.5,
                 extra_parameter=None, u_knots_to_add=0, v_knots_to_add=0, t_knots_to_add=0, tolerance=1e-4,
                 refine_tol=None):
        _RBF.__init__(self, original_control_points, deformed_control_points, func, radius, extra_parameter)
        CADDeformation.__init__(self, u_knots_to_add, v_knots_to_add, t_knots_to_add, tolerance, refine_tol)

    __call__ = CADDeformation.__call__


class IDW(CADDeformation, _IDW):
    """Inverse Distance Weighting deformation of CAD files (PyGeM's ``pygem.cad.IDW``)."""

    def __init__(self, original_control_points=None, deformed_control_points=None, power=2, u_knots_to_add=0,
                 v_knots_to_add=0, t_knots_to_add=0, tolerance=1e-4, refine_tol=None):
        _IDW.__init__(self, original_control_points, deformed_control_points, power)
        CADDeformation.__init__(self, u_knots_to_add, v_knots_to_add, t_knots_to_add, tolerance, refine_tol)

    __call__ = CADDeformation.__call__


class CustomDeformation(CADDeformation, _CustomDeformation):
    """A function's deformation of CAD files (PyGeM's ``pygem.cad.CustomDeformation``)."""

    def __init__(self, func, u_knots_to_add=0, v_knots_to_add=0, t_knots_to_add=0, tolerance=1e-4, refine_tol=None):
        _CustomDeformation.__init__(self, func)
        CADDeformation.__init__(self, u_knots_to_add, v_knots_to_add, t_knots_to_add, tolerance, refine_tol)

    __call__ = CADDeformation.__call__
