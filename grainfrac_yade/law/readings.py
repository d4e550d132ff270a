"""Readings: which stress drives a bond's stress corrosion (the rate of paper Eq. 7), pure numpy.

Paper Eq. 6 reads the driving stress of contact i as sigma_i = F_i / L_i.  In a model whose Voronoi face carries
several bonds (the face's nodes, ``resolution.nodes_per_face``), that sentence has two readings, selected by
``stress_corrosion.reading``:

* ``"node"`` (the default): each bond's own force over its own area, F_i / A_i, the stress its failure criterion
  (Eq. 4-5) reads too (UDEC's sub-contacts: a contact of deformable blocks is a boundary gridpoint with its own
  length, force and strength);
* ``"face"``: the paper's F / L over the whole face: every bond of a face corrodes at the rate of the face's
  resultant normal force (tension positive; broken bonds add the contact forces they carry) and its summed shear
  force magnitudes, over the face's whole area.  Failure stays per bond (Eq. 4-5 on the bond's own stress), so a
  face can fail part by part.  The summed magnitudes equal the resultant shear force where the face's bonds shear
  one way (a face that slides); a face whose bonds shear both ways (one that turns) reads more shear than its
  resultant.

A reading only sets the driving stresses of :class:`~grainfrac_yade.law.Stresses` (``rate_normal``,
``rate_shear``); the stresses the criteria read are the bonds' own in either.  Under frozen forces a face's
stresses are constant between events like a bond's, so the event clock's closed forms stay exact.
"""
from __future__ import annotations

import numpy as np

#: Values of ``stress_corrosion.reading``.
READING_NAMES = ("node", "face")

#: The laws that keep the driving stress apart from the stress their criteria read (Eq. 7's rate on one, Eq. 4-5 on
#: the other); the normalised and area laws tie the two (failure where the driving stress meets the strength).
FACE_READING_LAWS = ("hillig_charles",)


def face_stresses(bond_face, bond_area, normal_force, shear_force):
    """Every bond's face stresses: (sigma_face, tau_face) [Pa] per bond, the sums of ``normal_force`` (tension
    positive) and ``shear_force`` (magnitudes) [N] over each face's bonds, over the sum of their areas
    ``bond_area`` [m^2] (the face's area).  All arrays have one entry per bond of the scene."""
    face = np.asarray(bond_face, dtype=np.int64)
    n_faces = int(face.max()) + 1 if face.size else 0
    area = np.bincount(face, weights=np.asarray(bond_area, float), minlength=n_faces)
    fn = np.bincount(face, weights=np.asarray(normal_force, float), minlength=n_faces)
    fs = np.bincount(face, weights=np.asarray(shear_force, float), minlength=n_faces)
    return (fn / area)[face], (fs / area)[face]


class NodeReading:
    """Each bond corrodes at the rate of its own stress (the default)."""
    name = "node"

    def driving(self, index, normal, shear, scene):
        """The driving stresses of bonds ``index`` whose own stresses are ``normal``, ``shear``: those."""
        return normal, shear


class FaceReading:
    """Each bond corrodes at the rate of its face's stress (F / L over the whole face)."""
    name = "face"

    def __init__(self, bond_face, bond_area):
        self.bond_face = np.asarray(bond_face, dtype=np.int64)
        self.bond_area = np.asarray(bond_area, float)

    def driving(self, index, normal, shear, scene):
        """The face stresses of bonds ``index``, from the forces of every bond of the ``scene``
        (:meth:`~grainfrac_yade.engines.Scene.bond_forces`; a broken bond's force is the contact force it carries)."""
        fn, fs = scene.bond_forces(None)
        sigma, tau = face_stresses(self.bond_face, self.bond_area, fn, fs)
        return sigma[index], tau[index]


def build_reading(name: str, layout):
    """The reading ``name`` for the bonds of ``layout`` (its ``bond_face``, ``bond_area``)."""
    if name == NodeReading.name:
        return NodeReading()
    if name == FaceReading.name:
        return FaceReading(layout.bond_face, layout.bond_area)
    raise ValueError(f"no stress reading {name!r}; choose one of {', '.join(READING_NAMES)}")
