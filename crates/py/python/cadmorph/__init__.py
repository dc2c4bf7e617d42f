"""cadmorph: morph CAD (IGES/STEP) and point sets with FFD, RBF and IDW, keeping the seams joined.

The Python package of the Rust crates of cadmorph: everything here calls the Rust
implementation (the extension module ``cadmorph._native``); nothing is computed in Python.

Deformations take and return numpy ``float64`` arrays of shape ``(n, 3)``::

    import numpy as np, cadmorph
    ffd = cadmorph.read_parameters("samples/pygem/parameters_test_ffd_sphere.prm")
    moved = ffd(np.load("samples/pygem/meshpoints_sphere_orig.npy"))   # a new array
    ffd.deform(points, out=points)                                      # in place

CAD files::

    model = cadmorph.open("samples/hull3.igs")
    outcome = model.morph(ffd, refine_tol=1.45e-5)
    model.seams()                      # one dict per shared edge
    model.save("hull3_morphed.igs")

PyGeM scripts run with one changed import: ``import cadmorph.pygem as pygem`` (or
``from cadmorph.pygem import FFD``; ``from cadmorph.pygem.cad import FFD`` for files).

Classes: :class:`Ffd`, :class:`Rbf`, :class:`Idw`, :class:`Affine`, :class:`Composed`,
:class:`FromFunction`, :class:`Model`. Functions: :func:`open`, :func:`from_bytes`,
:func:`read_parameters`, :func:`parameters_from_str`, :func:`compose`,
:func:`set_num_threads`, :func:`num_threads`. Exceptions: :class:`ParameterError`,
:class:`CadFileError` (both ``ValueError``), carrying ``path``, ``line`` (and ``entity``).
"""

from ._native import (  # noqa: F401
    Affine,
    CadFileError,
    Composed,
    Ffd,
    FromFunction,
    Idw,
    Model,
    ParameterError,
    Rbf,
    __version__,
    compose,
    from_bytes,
    num_threads,
    open,
    parameters_from_str,
    read_parameters,
    set_num_threads,
)

__all__ = [
    "Affine",
    "CadFileError",
    "Composed",
    "Ffd",
    "FromFunction",
    "Idw",
    "Model",
    "ParameterError",
    "Rbf",
    "__version__",
    "compose",
    "from_bytes",
    "num_threads",
    "open",
    "parameters_from_str",
    "read_parameters",
    "set_num_threads",
]
