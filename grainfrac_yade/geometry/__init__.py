"""Specimen geometry (pure numpy/scipy; no YADE): the Voronoi tessellations of a box (:mod:`.tessellation`)
and of a disc (:mod:`.disc`), their regularisation (:mod:`.regularise`), the minerals' allocation to the
cells (:mod:`.minerals`), the specimen built from them (:mod:`.specimen`) and the cells' triangle meshes
(:mod:`.grainmesh`).  Import the modules themselves: this package's ``__init__`` loads none of them."""
