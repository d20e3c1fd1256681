"""A robot's real shape: the meshes drawn on its bodies (:mod:`studies.shape.meshes`: a URDF's visual
meshes kept by ``rmt import-urdf``, or a bundled arm's maker meshes from ``example-robot-data``) and the
mapping of a URDF's bodies onto a bundled arm's DH frames (:mod:`studies.shape.mapping`).  Used by the
reports' 3-D views and by ``rmt view``."""
