# PyGeM's tutorial 1 (tutorials/tutorial1/tutorial-1-ffd.py, "Free Form Deformation on
# Spherical Mesh") as a script for cadmorph: the computation is PyGeM's, line for line;
# the one changed line is the import (marked), and the plots are left out. A second part
# does the same FFD from a .prm file on PyGeM's sphere test data, as PyGeM's own FFD
# tests do. Usage: tutorial_1_ffd.py PRM SPHERE_POINTS.npy OUT.npz
import sys

import numpy as np

from cadmorph.pygem import FFD  # PyGeM: from pygem import FFD

np.random.seed(42)


def mesh_points(num_pts=2000):
    indices = np.arange(0, num_pts, dtype=float) + 0.5

    phi = np.arccos(1 - 2 * indices / num_pts)
    theta = np.pi * (1 + 5**0.5) * indices

    return np.array(
        [np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)]
    ).T


mesh = mesh_points()

ffd = FFD([2, 2, 2])
print(ffd)

print(
    "Movements of point[{}, {}, {}] along x: {}".format(
        1, 1, 1, ffd.array_mu_x[1, 1, 1]
    )
)
print(
    "Movements of point[{}, {}, {}] along z: {}".format(
        1, 1, 1, ffd.array_mu_z[1, 1, 1]
    )
)

ffd.array_mu_x[1, 1, 1] = 2
ffd.array_mu_z[1, 1, 1] = 0.8
print()
print(
    "Movements of point[{}, {}, {}] along x: {}".format(
        1, 1, 1, ffd.array_mu_x[1, 1, 1]
    )
)
print(
    "Movements of point[{}, {}, {}] along z: {}".format(
        1, 1, 1, ffd.array_mu_z[1, 1, 1]
    )
)

new_mesh = ffd(mesh)
print(type(new_mesh), new_mesh.shape)
control_points = ffd.control_points()

# The same FFD read from a parameter file, on a sphere point cloud.
ffd = FFD()
ffd.read_parameters(sys.argv[1])
sphere = np.load(sys.argv[2])
new_sphere = ffd(sphere)

np.savez(sys.argv[3], new_mesh=new_mesh, control_points=control_points, new_sphere=new_sphere)
